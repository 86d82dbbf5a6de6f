#include "sim/exact_linear.h"

#include <algorithm>
#include <cmath>
#include <Eigen/Eigenvalues>
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

namespace {

const Eigen::MatrixXd& LinearA(const ThermalNetwork& network) {
  if (!network.is_linear()) throw std::logic_error("ExactLinearPropagator needs a linear network");
  return network.A();
}

}  // namespace

ExactLinearPropagator::ExactLinearPropagator(const ThermalNetwork& network)
    : ExactLinearPropagator(network, LinearA(network)) {}

ExactLinearPropagator::ExactLinearPropagator(const ThermalNetwork& network, const Eigen::MatrixXd& A) {
  const Eigen::Index n = A.rows(), m = 1 + network.num_sources();
  M_ = Eigen::MatrixXd::Zero(n + 2 * m, n + 2 * m);
  M_.topLeftCorner(n, n) = A;
  M_.block(0, n, n, 1) = network.b_amb();
  M_.block(0, n + 1, n, m - 1) = network.B_src();
  M_.block(n, n + m, m, m).setIdentity();
  AB_ = M_.topLeftCorner(n, n + m);
  z_.resize(n + 2 * m);
  next_.resize(2 * n);
  sums_.resize(4 * n);
  // Modal form when A = V diag(lambda) V^-1 with real eigenvalues and a well-conditioned V,
  // which a thermal network always has (A = -C^-1 L with L symmetric positive definite is
  // similar to a symmetric matrix; sensor-lag followers add -1/tau; a folded power drift adds
  // a rank-one term that can break this, and then the Pade path is taken). Kept only when the
  // eigenvectors are far from degenerate (cond(V) < 1e6: round-off then stays ~1e-10, far
  // below any temperature resolution); otherwise the Pade exponential is used.
  const Eigen::EigenSolver<Eigen::MatrixXd> eig(A);
  if (eig.info() == Eigen::Success && eig.eigenvalues().imag().cwiseAbs().maxCoeff() <= 1e-12 * eig.eigenvalues().cwiseAbs().maxCoeff() &&
      (eig.eigenvalues().real().array() < 0.0).all()) {
    const Eigen::MatrixXd V = eig.eigenvectors().real();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(V);
    const double cond = svd.singularValues()(0) / svd.singularValues()(svd.singularValues().size() - 1);
    if (std::isfinite(cond) && cond < 1e6) {
      lambda_ = eig.eigenvalues().real();
      V_ = V;
      Vinv_ = V.inverse();
      W_ = Vinv_ * AB_.rightCols(m);  // V^-1 B
    }
  }
}

const Eigen::MatrixXd& ExactLinearPropagator::StepMatrix(double h) {
  // A few step sizes recur (the sample period, the first partial step, pieces at breakpoints):
  // keep the last kCacheSize of them, replacing round-robin.
  for (auto& entry : cache_)
    if (entry.first == h) return entry.second;
  const Eigen::Index n = AB_.rows(), m = AB_.cols() - n;
  Eigen::MatrixXd target(2 * n, n + 2 * m);
  if (lambda_.size() == n) {
    // Per mode: e^(l h), int_0^h e^(l s) ds = h phi1(l h), int_0^h e^(l (h - s)) s ds = h^2 phi2(l h),
    // phi1(x) = (e^x - 1) / x, phi2(x) = (e^x - 1 - x) / x^2 (series near 0 against cancellation).
    Eigen::VectorXd e(n), g0(n), g1(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const double x = lambda_[i] * h;
      e[i] = std::exp(x);
      const double phi1 = std::abs(x) < 1e-5 ? 1.0 + x / 2.0 + x * x / 6.0 : std::expm1(x) / x;
      const double phi2 = std::abs(x) < 1e-3 ? 0.5 + x / 6.0 + x * x / 24.0 + x * x * x / 120.0 : (std::expm1(x) - x) / (x * x);
      g0[i] = h * phi1;
      g1[i] = h * h * phi2;
    }
    target.block(0, 0, n, n).noalias() = V_ * e.asDiagonal() * Vinv_;
    target.block(0, n, n, m).noalias() = V_ * g0.asDiagonal() * W_;
    target.block(0, n + m, n, m).noalias() = V_ * g1.asDiagonal() * W_;
  } else {
    const Eigen::MatrixXd Mh = M_ * h;
    target.topRows(n) = Mh.exp().topRows(n);
  }
  // xdot(t + h) = A x(t + h) + B (u + v h). Top and bottom rows do not overlap: no alias.
  target.bottomRows(n).noalias() = AB_.leftCols(n) * target.topRows(n);
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
  if (piece_.rows() != 2 * n) throw std::logic_error("ExactLinearPropagator::Advance before BeginPiece");
  // AffineRows reads a copy of x, not x in place: reading x in place took BM_Simulate16NodeNetwork
  // from 17.9 to 20.5 ms (least of 15 - 20 alternating runs), though neither aliases next_.
  double* const z = z_.data();
  for (Eigen::Index i = 0; i < n; ++i) z[i] = x[i];
  AffineRows<0>(piece_.data(), 2 * n, n, z, tau, next_.data(), 2 * n, sums_.data());
  for (Eigen::Index i = 0; i < n; ++i) x[i] = next_[i], xdot[i] = next_[n + i];
}

}  // namespace rlg::sim
