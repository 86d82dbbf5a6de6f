#pragma once
/// Exact propagation of a linear network whose inputs are linear over each step:
///
///   xdot = A x + B u(t),   u(t_k + s) = u_k + v s  (0 <= s <= h)
///   x(t_k + h) = Phi x_k + Gamma0 u_k + Gamma1 v,
///
/// with [Phi Gamma0 Gamma1] the top block row of exp(h M), M = [[A, B, 0], [0, 0, I], [0, 0, 0]]
/// (Van Loan's augmented-matrix method; Eigen's matrix exponential). u = [T_amb, P_1 .. P_s].
/// When A has real eigenvalues and well-conditioned eigenvectors (every thermal network), the
/// same blocks come from its modal form, which costs O(n^3) instead of a Pade exponential of
/// the (n + 2m)-square augmented matrix: what irregular sample times need, where every step
/// has its own h.
/// Exact to round-off, so it is both the oracle for the CVODE path and, for linear networks
/// with piecewise-linear inputs (constant, ramp, table, steps), the fast path. Inside one input
/// piece (u(t0 + tau) = u0 + v tau) with a fixed step h the input terms are affine in tau,
///   x(t0 + tau + h) = Phi x(t0 + tau) + f0 + tau f1,   f0 = Gamma0 u0 + Gamma1 v,  f1 = Gamma0 v,
/// so BeginPiece forms [Phi f0 f1] once and each sample costs one n x (n + 2) product (and the
/// same for the derivative rows).

#include <Eigen/Dense>
#include <utility>
#include <vector>

#include "sim/thermal_network.h"

namespace rlg::sim {

class ExactLinearPropagator {
 public:
  /// Precondition: network.is_linear().
  explicit ExactLinearPropagator(const ThermalNetwork& network);
  /// The network's inputs (ambient and sources) with another system matrix A, e.g. the
  /// network's own with its power drift folded in at constant power (ThermalNetwork::FoldDrift).
  ExactLinearPropagator(const ThermalNetwork& network, const Eigen::MatrixXd& A);

  /// Advances x over h with inputs u (at the start) and slope v (per s), and writes the
  /// derivative at the end of the step, xdot = A x + B (u + v h), from the same product.
  void Step(double h, const Eigen::Ref<const Eigen::VectorXd>& u, const Eigen::Ref<const Eigen::VectorXd>& v,
            Eigen::Ref<Eigen::VectorXd> x, Eigen::Ref<Eigen::VectorXd> xdot);

  /// Prepares steps of length h inside an input piece starting at t0 with inputs u0 and slope v.
  void BeginPiece(double h, const Eigen::Ref<const Eigen::VectorXd>& u0, const Eigen::Ref<const Eigen::VectorXd>& v);
  /// Advances x from t0 + tau to t0 + tau + h of the current piece, as Step would, and writes
  /// the derivative there. Precondition: BeginPiece was called (std::logic_error otherwise).
  void Advance(double tau, Eigen::Ref<Eigen::VectorXd> x, Eigen::Ref<Eigen::VectorXd> xdot);
  /// Advance for a network of N states known at compile time, on the caller's state x (which
  /// it may keep in registers) and derivative xdot: the same operations in the same order, so
  /// the same bytes. Precondition: BeginPiece was called for a network of N states.
  /// Plain loops, not Eigen's packets: a caller compiled for wider vectors (the simulator's
  /// AVX2 path) gets them here too, with the same products and sums in the same order.
  /// kRates = false: the state only, xdot left as it was (half the products, for a caller that
  /// reads no derivative); the state's rows are the same operations either way.
  template <int N, bool kRates = true>
  [[gnu::always_inline]] inline void AdvanceFixed(double tau, Eigen::Matrix<double, N, 1>& x, double* xdot) const {
    AdvanceFixed<N, kRates>(tau, x.data(), xdot);
  }
  /// The same on a plain array of N states, which a caller's loop can keep in registers.
  template <int N, bool kRates = true>
  [[gnu::always_inline]] inline void AdvanceFixed(double tau, double* x, double* xdot) const {
    constexpr int kStride = 2 * N, kRows = kRates ? 2 * N : N;  // S's column length; rows made
    double next[kRows];
    AffineRows<kRows>(piece_.data(), kStride, N, x, tau, next);
    for (int r = 0; r < N; ++r) x[r] = next[r];
    if constexpr (kRates) {
      for (int r = 0; r < N; ++r) xdot[r] = next[N + r];
    }
  }

  /// out[r] = sum_j S(r, j) x_j + (S(r, n) + tau S(r, n + 1)) for the first `rows` rows of the
  /// column-major S (column length `stride`), in the order every regular step uses (Advance
  /// and AdvanceFixed): the input term first, which needs no state; the states' products in two
  /// sums, even and odd j, each in increasing j; then (even + odd) + input. The chain from one
  /// sample's state to the next is a product and ceil(n / 2) + 1 additions (16 cycles for four
  /// states at 4 cycles an operation), not a product and n + 2 additions in a row (28).
  /// kRows > 0: `rows` known at compile time (unrolled; the caller keeps x in registers);
  /// kRows = 0: any `rows`, with `scratch` room for 2 rows values.
  template <int kRows>
  [[gnu::always_inline]] static inline void AffineRows(const double* S, Eigen::Index stride, Eigen::Index n,
                                                       const double* x, double tau, double* out, Eigen::Index rows = kRows,
                                                       double* scratch = nullptr) {
    constexpr int kMax = kRows > 0 ? kRows : 1;
    double input[kMax], even[kMax], odd[kMax];
    if constexpr (kRows > 0) {
      for (int r = 0; r < kRows; ++r) input[r] = S[n * stride + r] + tau * S[(n + 1) * stride + r];
      for (int r = 0; r < kRows; ++r) even[r] = x[0] * S[r];
      if (n == 1) {
        for (int r = 0; r < kRows; ++r) out[r] = even[r] + input[r];
        return;
      }
      for (int r = 0; r < kRows; ++r) odd[r] = x[1] * S[stride + r];
      for (Eigen::Index j = 2; j < n; ++j) {
        double* const sum = j % 2 == 0 ? even : odd;
        for (int r = 0; r < kRows; ++r) sum[r] += x[j] * S[j * stride + r];
      }
      for (int r = 0; r < kRows; ++r) out[r] = (even[r] + odd[r]) + input[r];
    } else {
      // Column by column (contiguous, vectorised), the same operations per row as above.
      double* __restrict const sum_even = scratch;  // apart from S, x and out: vectorised
      double* __restrict const sum_odd = scratch + rows;
      for (Eigen::Index r = 0; r < rows; ++r) sum_even[r] = x[0] * S[r];
      if (n > 1) {
        for (Eigen::Index r = 0; r < rows; ++r) sum_odd[r] = x[1] * S[stride + r];
      }
      for (Eigen::Index j = 2; j < n; ++j) {
        double* __restrict const sum = j % 2 == 0 ? sum_even : sum_odd;
        const double xj = x[j];
        const double* __restrict const column = S + j * stride;
        for (Eigen::Index r = 0; r < rows; ++r) sum[r] += xj * column[r];
      }
      for (Eigen::Index r = 0; r < rows; ++r) {
        const double input_r = S[n * stride + r] + tau * S[(n + 1) * stride + r];
        out[r] = n > 1 ? (sum_even[r] + sum_odd[r]) + input_r : sum_even[r] + input_r;
      }
    }
  }

 private:
  const Eigen::MatrixXd& StepMatrix(double h);
  Eigen::MatrixXd M_;       // augmented generator
  Eigen::MatrixXd AB_;      // [A B]: the right-hand side's linear map of [x; u]
  /// (h, [[Phi Gamma0 Gamma1], [A Phi, A Gamma0 + B, A Gamma1 + B h]]) for recent step sizes
  static constexpr size_t kCacheSize = 4;
  std::vector<std::pair<double, Eigen::MatrixXd>> cache_;
  size_t next_slot_ = 0;
  Eigen::VectorXd z_, next_;
  Eigen::VectorXd sums_;  // AffineRows's scratch in Advance: 2 x 2n
  Eigen::MatrixXd piece_;
  // Modal form of A (empty when A is not safely diagonalisable): eigenvalues, V, V^-1, V^-1 B.
  Eigen::VectorXd lambda_;
  Eigen::MatrixXd V_, Vinv_, W_;  // [[Phi f0 f1], [A Phi, A f0 + B u0 + B v h, A f1 + B v]]: 2n x (n + 2)
};

}  // namespace rlg::sim
