#include "diagnosis/statistics/ar_noise.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace rlg::diagnosis {

namespace {

/// c_0..c_max pooled over segments, each about its own mean (divided by all values).
std::vector<double> Autocovariances(const std::vector<std::vector<double>>& segments, int max_lag, size_t* count) {
  std::vector<double> c(static_cast<size_t>(max_lag) + 1, 0.0);
  size_t n = 0;
  for (const auto& s : segments) {
    if (s.empty()) continue;
    double mean = 0.0;
    for (double v : s) mean += v;
    mean /= static_cast<double>(s.size());
    for (int h = 0; h <= max_lag; ++h)
      for (size_t k = 0; k + static_cast<size_t>(h) < s.size(); ++k)
        c[static_cast<size_t>(h)] += (s[k] - mean) * (s[k + static_cast<size_t>(h)] - mean);
    n += s.size();
  }
  for (double& v : c) v /= static_cast<double>(std::max<size_t>(n, 1));
  *count = n;
  return c;
}

/// Levinson-Durbin over orders 1..cap: the model of least AIC, or with `fixed` the model of
/// order cap (phi padded with zeros where the recursion stops early).
ArModel YuleWalker(const std::vector<std::vector<double>>& segments, int max_order, bool fixed) {
  size_t n = 0;
  for (const auto& s : segments) n += s.size();
  const int cap = std::max(0, std::min(max_order, static_cast<int>(n / 10)));
  const std::vector<double> c = Autocovariances(segments, cap, &n);
  ArModel best;
  if (n < 3 || !(c[0] > 0.0)) return best;
  // Levinson-Durbin: phi of order p from order p - 1, v the innovation variance.
  std::vector<double> phi, prev;
  double v = c[0], aic_best = static_cast<double>(n) * std::log(v), product = 1.0;
  best.sigma = std::sqrt(v);
  best.sd = std::sqrt(c[0]);
  for (int p = 1; p <= cap; ++p) {
    double acc = c[static_cast<size_t>(p)];
    for (int i = 1; i < p; ++i) acc -= prev[static_cast<size_t>(i - 1)] * c[static_cast<size_t>(p - i)];
    const double k = acc / v;
    if (!(std::abs(k) < 1.0)) break;  // round-off at a perfectly predictable series
    phi.assign(static_cast<size_t>(p), 0.0);
    for (int i = 1; i < p; ++i) phi[static_cast<size_t>(i - 1)] = prev[static_cast<size_t>(i - 1)] - k * prev[static_cast<size_t>(p - i - 1)];
    phi[static_cast<size_t>(p - 1)] = k;
    v *= 1.0 - k * k;
    product *= 1.0 - k * k;
    prev = phi;
    const double aic = static_cast<double>(n) * std::log(v) + 2.0 * p;
    if (fixed || aic < aic_best) {
      aic_best = aic;
      best.phi = phi;
      best.sigma = std::sqrt(v);
      best.sd = std::sqrt(v / product);
    }
  }
  if (fixed) best.phi.resize(static_cast<size_t>(cap), 0.0);
  // The fitted process's lag-1 autocorrelation: the Yule-Walker equations reproduce c_1 / c_0
  // for p >= 1 (and 0 for white noise).
  best.rho1 = best.phi.empty() ? 0.0 : c[1] / c[0];
  return best;
}

}  // namespace

ArModel FitAr(const std::vector<std::vector<double>>& segments, int max_order) {
  return YuleWalker(segments, max_order, false);
}

ArModel FitArOfOrder(const std::vector<std::vector<double>>& segments, int order) {
  return YuleWalker(segments, order, true);
}

std::vector<double> SimulateAr(const ArModel& m, size_t n, sim::Rng& rng) {
  const size_t burn = std::max<size_t>(n, 500), p = m.phi.size();
  std::vector<double> e(burn + n, 0.0);
  for (size_t k = 0; k < e.size(); ++k) {
    double v = m.sigma * rng.Normal();
    for (size_t i = 1; i <= p && i <= k; ++i) v += m.phi[i - 1] * e[k - i];
    e[k] = v;
  }
  return {e.begin() + static_cast<std::ptrdiff_t>(burn), e.end()};
}

}  // namespace rlg::diagnosis
