#include "sim/exact_linear.h"

#include <algorithm>
#include <stdexcept>
#include <unsupported/Eigen/MatrixFunctions>

namespace rlg::sim {

ExactLinearPropagator::ExactLinearPropagator(const ThermalNetwork& network) {
  if (!network.is_linear()) throw std::logic_error("ExactLinearPropagator needs a linear network");
  const Eigen::Index n = network.num_states(), m = 1 + network.num_sources();
  M_ = Eigen::MatrixXd::Zero(n + 2 * m, n + 2 * m);
  M_.topLeftCorner(n, n) = network.A();
  M_.block(0, n, n, 1) = network.b_amb();
  M_.block(0, n + 1, n, m - 1) = network.B_src();
  M_.block(n, n + m, m, m).setIdentity();
  AB_ = M_.topLeftCorner(n, n + m);
  z_.resize(n + 2 * m);
  next_.resize(2 * n);
}

const Eigen::MatrixXd& ExactLinearPropagator::StepMatrix(double h) {
  // A few step sizes recur (the sample period, the first partial step, pieces at breakpoints):
  // keep the last kCacheSize of them, replacing round-robin.
  for (auto& entry : cache_)
    if (entry.first == h) return entry.second;
  const Eigen::Index n = AB_.rows(), m = AB_.cols() - n;
  const Eigen::MatrixXd Mh = M_ * h;
  const Eigen::MatrixXd E = Mh.exp();
  Eigen::MatrixXd target(2 * n, n + 2 * m);
  target.topRows(n) = E.topRows(n);
  // xdot(t + h) = A x(t + h) + B (u + v h).
  target.bottomRows(n).noalias() = AB_.leftCols(n) * E.topRows(n);
  target.block(n, n, n, m) += AB_.rightCols(m);
  target.block(n, n + m, n, m) += h * AB_.rightCols(m);
  if (cache_.size() < kCacheSize) {
    cache_.emplace_back(h, std::move(target));
    return cache_.back().second;
  }
  auto& slot = cache_[next_slot_];
  next_slot_ = (next_slot_ + 1) % kCacheSize;
  slot = {h, std::move(target)};
  return slot.second;
}

void ExactLinearPropagator::Step(double h, const Eigen::Ref<const Eigen::VectorXd>& u,
                                 const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::Ref<Eigen::VectorXd> x,
                                 Eigen::Ref<Eigen::VectorXd> xdot) {
  const Eigen::MatrixXd& step = StepMatrix(h);
  const Eigen::Index n = x.size(), m = u.size();
  z_.head(n) = x;
  z_.segment(n, m) = u;
  z_.tail(m) = v;
  // next = step * z as column axpys over raw storage: for these tiny dynamic matrices Eigen's
  // general kernels spend more on dispatch than on arithmetic (measured: ~3x the instructions).
  // __restrict: the three arrays never overlap, which lets the compiler vectorise the axpy.
  const Eigen::Index rows = step.rows(), cols = step.cols();
  double* __restrict const out = next_.data();
  const double* __restrict const z = z_.data();
  const double* __restrict col = step.data();
  std::fill(out, out + rows, 0.0);
  for (Eigen::Index j = 0; j < cols; ++j, col += rows) {
    const double zj = z[j];
    for (Eigen::Index i = 0; i < rows; ++i) out[i] += zj * col[i];
  }
  x = next_.head(n);
  xdot = next_.tail(n);
}

}  // namespace rlg::sim
