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
  // The regular sample period is cached; the odd partial steps at input breakpoints are rare
  // (a few per run) and computed on the spot without evicting it.
  Eigen::MatrixXd& target = (h_cached_ < 0.0 || h == h_cached_) ? step_ : scratch_;
  if (h != h_cached_ || &target == &scratch_) {
    const Eigen::Index n = AB_.rows(), m = AB_.cols() - n;
    const Eigen::MatrixXd Mh = M_ * h;
    const Eigen::MatrixXd E = Mh.exp();
    target.resize(2 * n, n + 2 * m);
    target.topRows(n) = E.topRows(n);
    // xdot(t + h) = A x(t + h) + B (u + v h).
    target.bottomRows(n).noalias() = AB_.leftCols(n) * E.topRows(n);
    target.block(n, n, n, m) += AB_.rightCols(m);
    target.block(n, n + m, n, m) += h * AB_.rightCols(m);
    if (&target == &step_) h_cached_ = h;
  }
  return target;
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
  const Eigen::Index rows = step.rows(), cols = step.cols();
  double* const out = next_.data();
  const double* col = step.data();
  std::fill(out, out + rows, 0.0);
  for (Eigen::Index j = 0; j < cols; ++j, col += rows) {
    const double zj = z_[j];
    for (Eigen::Index i = 0; i < rows; ++i) out[i] += zj * col[i];
  }
  x = next_.head(n);
  xdot = next_.tail(n);
}

}  // namespace rlg::sim
