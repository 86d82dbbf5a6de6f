#include "diagnosis/statistics/score.h"

#include <algorithm>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>

#include "sim/stats.h"

namespace rlg::diagnosis {

double ResidualFit::rms() const { return n ? std::sqrt(ssr / n) : 0.0; }

ResidualFit Summarise(const std::vector<std::vector<double>>& series) {
  ResidualFit f;
  double c1 = 0.0;
  for (const auto& s : series) {
    for (size_t i = 0; i < s.size(); ++i) {
      f.ssr += s[i] * s[i];
      if (i > 0) c1 += s[i] * s[i - 1];
    }
    f.n += static_cast<int>(s.size());
  }
  f.rho = f.ssr > 0.0 ? std::clamp(c1 / f.ssr, 0.0, 0.9) : 0.0;
  return f;
}

double InformationGain(const ResidualFit& base, const ResidualFit& ext, int added_parameters) {
  const double n_eff = base.n * (1.0 - base.rho) / (1.0 + base.rho);
  const double var = base.ssr / base.n;
  return (base.ssr - ext.ssr) / var * (n_eff / base.n) - added_parameters * std::log(std::max(n_eff, 2.0));
}

double HeldOutRmsRatio(double ssr_base, double ssr_ext) { return ssr_ext > 0.0 ? std::sqrt(ssr_base / ssr_ext) : 1.0; }

double LogLikelihoodRatio(const ResidualFit& base, const ResidualFit& ext) {
  if (base.n <= 0 || ext.n <= 0 || !(base.ssr > 0.0)) return 0.0;
  return static_cast<double>(base.n) * std::log(base.ssr / std::max(ext.ssr, 1e-300 * base.ssr));
}

double LjungBoxP(const std::vector<double>& x, int lags) {
  const size_t n = x.size();
  if (n <= static_cast<size_t>(lags) + 1) return 1.0;
  const double mean = sim::Mean(x);
  double c0 = 0.0;
  for (double v : x) c0 += (v - mean) * (v - mean);
  if (!(c0 > 0.0)) return 1.0;
  double q = 0.0;
  for (int k = 1; k <= lags; ++k) {
    double ck = 0.0;
    for (size_t i = k; i < n; ++i) ck += (x[i] - mean) * (x[i - k] - mean);
    const double rho = ck / c0;
    q += rho * rho / static_cast<double>(n - k);
  }
  q *= static_cast<double>(n) * (static_cast<double>(n) + 2.0);
  return boost::math::cdf(boost::math::complement(boost::math::chi_squared(lags), q));
}

double NullThreshold(const std::vector<double>& replicate_scores, double min_score) {
  double top = min_score;
  for (double s : replicate_scores) top = std::max(top, s);
  return top;
}

}  // namespace rlg::diagnosis
