#include "validation/order_statistics.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "sim/errors.h"

namespace rlg::validation {

namespace {

/// Term j of Binomial(n, p)'s probability mass, in log space (lgamma) for any n.
double BinomialTerm(uint64_t j, uint64_t n, double lp, double lq) {
  const double nn = static_cast<double>(n), jj = static_cast<double>(j);
  return std::exp(std::lgamma(nn + 1.0) - std::lgamma(jj + 1.0) - std::lgamma(nn - jj + 1.0) + jj * lp + (nn - jj) * lq);
}

}  // namespace

double BinomialCdf(int64_t k, uint64_t n, double p) {
  if (k < 0) return 0.0;
  if (static_cast<uint64_t>(k) >= n) return 1.0;
  if (p <= 0.0) return 1.0;
  if (p >= 1.0) return 0.0;
  const double lp = std::log(p), lq = std::log1p(-p);
  double sum = 0.0;
  for (int64_t j = 0; j <= k; ++j) sum += BinomialTerm(static_cast<uint64_t>(j), n, lp, lq);
  return std::min(sum, 1.0);
}

QuantileRanks QuantileInterval(uint64_t n, double q, double level) {
  if (n < 1 || !(q > 0.0 && q < 1.0) || !(level > 0.0 && level < 1.0)) {
    throw InputError(fmt::format("a quantile interval needs n >= 1, q and level in (0, 1); got n = {}, q = {:g}, level = {:g}",
                                 n, q, level));
  }
  const double a = 0.5 * (1.0 - level);
  QuantileRanks r;
  // Ranks in index order: F(l - 1) rises with l, so the last l with F(l - 1) <= a is found by
  // walking up; the first u with F(u - 1) >= 1 - a likewise.
  // F[k] = P(B <= k), k = 0..n: BinomialCdf's sums, the same terms added in the same order, as
  // one running sum (linear in n; a population of 10,000 gyros asks it for every metric).
  std::vector<double> F(n + 1);
  const double lp = std::log(q), lq = std::log1p(-q);
  double sum = 0.0;
  for (uint64_t k = 0; k < n; ++k) {
    sum += BinomialTerm(k, n, lp, lq);
    F[k] = std::min(sum, 1.0);
  }
  F[n] = 1.0;
  r.lower = 0;
  for (uint64_t l = 1; l <= n; ++l) {
    if (F[l - 1] <= a) r.lower = l;
  }
  r.upper = n + 1;
  for (uint64_t u = n; u >= 1; --u) {
    if (F[u - 1] >= 1.0 - a) r.upper = u;
  }
  const double hi = r.upper == n + 1 ? 1.0 : F[r.upper - 1];
  const double lo = r.lower == 0 ? 0.0 : F[r.lower - 1];
  r.coverage = hi - lo;
  return r;
}

uint64_t DrawsToBound(double q, double level) {
  // Both sides close once n is past max(log(a) / log(q), log(a) / log(1 - q)), a = (1 - level) / 2:
  // a few thousand for the quantiles and levels any plan asks.
  for (uint64_t n = 1;; ++n) {
    const QuantileRanks r = QuantileInterval(n, q, level);
    if (r.lower >= 1 && r.upper <= n) return n;
  }
}

std::pair<std::optional<double>, std::optional<double>> QuantileIntervalValues(std::vector<double> values, double q,
                                                                               double level) {
  const QuantileRanks r = QuantileInterval(values.size(), q, level);
  std::sort(values.begin(), values.end());
  std::pair<std::optional<double>, std::optional<double>> out;
  if (r.lower >= 1) out.first = values[r.lower - 1];
  if (r.upper <= values.size()) out.second = values[r.upper - 1];
  return out;
}

}  // namespace rlg::validation
