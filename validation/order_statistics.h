#pragma once
/// A distribution-free confidence interval for a quantile from the order statistics of n
/// independent draws (no assumption on the distribution): with X_(1) <= ... <= X_(n) and
/// B = #{X_i <= xi_q} ~ Binomial(n, q),
///
///   P(X_(l) <= xi_q <= X_(u)) = P(l <= B <= u - 1) = F(u - 1) - F(l - 1),   F the CDF of B.
///
/// QuantileInterval chooses l as the largest rank with F(l - 1) <= (1 - level)/2 and u as the
/// smallest with F(u - 1) >= (1 + level)/2, so each side misses with at most (1 - level)/2 and
/// the coverage F(u - 1) - F(l - 1) is at least `level` (above it, since B is discrete). When
/// n is too small for a side (l = 0: F(0) above (1 - level)/2; u = n + 1: F(n - 1) below
/// (1 + level)/2) that side is unbounded: for the p95 at 90 %, n >= 59 gyros bound it above
/// (1 - 0.95^59 >= 0.95).

#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

namespace rlg::validation {

struct QuantileRanks {
  uint64_t lower = 0;    ///< 1-based rank of the lower end; 0: unbounded below
  uint64_t upper = 0;    ///< 1-based rank of the upper end; n + 1: unbounded above
  double coverage = 0.0; ///< F(upper - 1) - F(lower - 1), the exact probability of covering xi_q
};

/// CDF of Binomial(n, p) at k (k < 0: 0; k >= n: 1), summed in log space (lgamma) for any n.
double BinomialCdf(int64_t k, uint64_t n, double p);

/// The ranks above for quantile q in (0, 1) and `level` in (0, 1); n >= 1.
QuantileRanks QuantileInterval(uint64_t n, double q, double level);

/// The fewest draws whose interval for quantile q at `level` is bounded on both sides (59 for
/// the p95 at 90 %). Same domain as QuantileInterval.
uint64_t DrawsToBound(double q, double level);

/// The interval's ends in the values (not sorted in place): nullopt for an unbounded side.
std::pair<std::optional<double>, std::optional<double>> QuantileIntervalValues(std::vector<double> values, double q,
                                                                               double level);

}  // namespace rlg::validation
