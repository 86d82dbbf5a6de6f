#include "sim/exact_linear.h"

#include <algorithm>
#include <stdexcept>
#include <unsupported/Eigen/MatrixFunctions>

namespace rlg::sim {
namespace {

/// out = S z for an R x cols column-major S, one fixed-size column at a time.
template <int R>
void Product(const double* S, const double* z, Eigen::Index cols, double* out) {
  Eigen::Matrix<double, R, 1> acc = Eigen::Matrix<double, R, 1>::Zero();
  for (Eigen::Index j = 0; j < cols; ++j) acc.noalias() += z[j] * Eigen::Map<const Eigen::Matrix<double, R, 1>>(S + j * R);
  Eigen::Map<Eigen::Matrix<double, R, 1>> result(out);
  result = acc;
}

/// out = S z for a rows x cols column-major S. Raw loops over raw storage: for these tiny
/// dynamic matrices Eigen's general kernels cost more than the arithmetic (callgrind: ~3x the
/// instructions); fixed-size columns for the usual small networks (unrolled, vectorised).
/// __restrict: the arrays never overlap, which lets the compiler vectorise the axpys.
void Product(const Eigen::MatrixXd& S, const double* __restrict z, double* __restrict out) {
  const Eigen::Index rows = S.rows(), cols = S.cols();
  switch (rows) {
    case 2: Product<2>(S.data(), z, cols, out); return;
    case 4: Product<4>(S.data(), z, cols, out); return;
    case 6: Product<6>(S.data(), z, cols, out); return;
    case 8: Product<8>(S.data(), z, cols, out); return;
    case 10: Product<10>(S.data(), z, cols, out); return;
    case 12: Product<12>(S.data(), z, cols, out); return;
    default: break;
  }
  const double* __restrict col = S.data();
  for (Eigen::Index i = 0; i < rows; ++i) out[i] = 0.0;
  for (Eigen::Index j = 0; j < cols; ++j, col += rows) {
    const double zj = z[j];
    for (Eigen::Index i = 0; i < rows; ++i) out[i] += zj * col[i];
  }
}

}  // namespace

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
  double* const z = z_.data();
  for (Eigen::Index i = 0; i < n; ++i) z[i] = x[i];
  for (Eigen::Index i = 0; i < m; ++i) z[n + i] = u[i], z[n + m + i] = v[i];
  Product(step, z, next_.data());
  for (Eigen::Index i = 0; i < n; ++i) x[i] = next_[i], xdot[i] = next_[n + i];
}

void ExactLinearPropagator::BeginPiece(double h, const Eigen::Ref<const Eigen::VectorXd>& u0,
                                       const Eigen::Ref<const Eigen::VectorXd>& v) {
  const Eigen::MatrixXd& step = StepMatrix(h);
  const Eigen::Index n = AB_.rows(), m = u0.size();
  piece_.resize(2 * n, n + 2);
  piece_.leftCols(n) = step.leftCols(n);
  // Step from t0 + tau: Gamma0 (u0 + v tau) + Gamma1 v = (Gamma0 u0 + Gamma1 v) + tau Gamma0 v.
  piece_.col(n).noalias() = step.middleCols(n, m) * u0 + step.rightCols(m) * v;
  piece_.col(n + 1).noalias() = step.middleCols(n, m) * v;
}

void ExactLinearPropagator::Advance(double tau, Eigen::Ref<Eigen::VectorXd> x, Eigen::Ref<Eigen::VectorXd> xdot) {
  const Eigen::Index n = x.size();
  double* const z = z_.data();
  for (Eigen::Index i = 0; i < n; ++i) z[i] = x[i];
  z[n] = 1.0;
  z[n + 1] = tau;
  Product(piece_, z, next_.data());
  for (Eigen::Index i = 0; i < n; ++i) x[i] = next_[i], xdot[i] = next_[n + i];
}

}  // namespace rlg::sim
