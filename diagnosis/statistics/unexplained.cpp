#include "diagnosis/statistics/unexplained.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <limits>

#include "diagnosis/statistics/score.h"

namespace rlg::diagnosis {

bool UnexplainedOptions::IsValid(std::string* error) const {
  std::string why;
  if (!(min_rms_over_noise >= 1.0))
    why = fmt::format("min_rms_over_noise must be at least 1 (got {:g})", min_rms_over_noise);
  else if (!(max_ljung_box_p > 0.0 && max_ljung_box_p <= 1.0))
    why = fmt::format("max_ljung_box_p must be in (0, 1] (got {:g})", max_ljung_box_p);
  if (error) *error = why;
  return why.empty();
}

double WhiteNoiseSd(const std::vector<double>& v) {
  if (v.size() < 5) return 0.0;
  std::vector<double> d2;  // squared fourth differences
  for (size_t k = 2; k + 2 < v.size(); ++k)
    d2.push_back(std::pow(v[k + 2] - 4.0 * v[k + 1] + 6.0 * v[k] - 4.0 * v[k - 1] + v[k - 2], 2));
  // Start: the smallest 90 % (E[z² | |z| < 1.6449] = 1 - 2 c phi(c) / 0.9 = 0.6230, z normal).
  std::vector<double> sorted = d2;
  const size_t keep = std::max<size_t>(1, static_cast<size_t>(std::floor(0.90 * static_cast<double>(d2.size()))));
  std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(keep - 1), sorted.end());
  double var = 0.0;
  for (size_t k = 0; k < keep; ++k) var += sorted[k];
  var /= static_cast<double>(keep) * 0.6230;
  // Then clipped at 3 sd until the kept set holds (E[z² | |z| < 3] = 0.97334).
  size_t kept_before = 0;
  for (int pass = 0; pass < 20 && var > 0.0; ++pass) {
    double sum = 0.0;
    size_t kept = 0;
    for (double d : d2)
      if (d < 9.0 * var) sum += d, ++kept;
    if (kept == 0) break;
    var = sum / static_cast<double>(kept) / 0.97334;
    if (kept == kept_before) break;
    kept_before = kept;
  }
  return std::sqrt(var / 70.0);
}

double Correlation(const std::vector<double>& x, const std::vector<double>& y) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (x.size() != y.size() || x.size() < 3) return nan;
  const double n = static_cast<double>(x.size());
  double mx = 0.0, my = 0.0;
  for (size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= n;
  my /= n;
  double sxy = 0.0, sxx = 0.0, syy = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
    syy += (y[i] - my) * (y[i] - my);
  }
  if (!(sxx > 0.0) || !(syy > 0.0)) return nan;
  return std::clamp(sxy / std::sqrt(sxx * syy), -1.0, 1.0);
}

std::vector<Unexplained> FindUnexplained(const std::vector<ChannelResidual>& channels, const UnexplainedOptions& options) {
  std::vector<Unexplained> out;
  for (const auto& c : channels) {
    if (!(c.score_block_noise > 0.0) || c.residual.empty() || c.t_s.size() != c.residual.size()) continue;
    const size_t g = static_cast<size_t>(std::max(1, c.fit_blocks_per_score));
    std::vector<double> means;
    for (size_t i = 0; i + g <= c.residual.size(); i += g) {
      double sum = 0.0;
      for (size_t k = i; k < i + g; ++k) sum += c.residual[k];
      means.push_back(sum / static_cast<double>(g));
    }
    if (means.empty()) continue;
    double ss = 0.0;
    for (double m : means) ss += m * m;
    Unexplained u;
    u.channel = c.channel;
    u.run = c.run;
    u.noise = c.score_block_noise;
    u.rms_over_noise = std::sqrt(ss / static_cast<double>(means.size())) / c.score_block_noise;
    u.ljung_box_p = LjungBoxP(c.residual, 10);
    if (!(u.rms_over_noise > options.min_rms_over_noise) || !(u.ljung_box_p < options.max_ljung_box_p)) continue;
    // Where: the stretch of consecutive score blocks with the largest total of (mean / s)² - 2
    // (Kadane's maximum subarray): a block of pure noise adds -1 on average, one carrying a
    // residual of 3 s adds about 8, so a stretch survives the odd noisy block inside it.
    size_t best_from = 0, best_len = 0, from = 0;
    double best = -std::numeric_limits<double>::infinity(), run_sum = 0.0;
    for (size_t i = 0; i < means.size(); ++i) {
      const double x = std::pow(means[i] / c.score_block_noise, 2) - 2.0;
      if (run_sum <= 0.0) run_sum = 0.0, from = i;
      run_sum += x;
      if (run_sum > best) best = run_sum, best_from = from, best_len = i - from + 1;
    }
    u.t_s = {c.t_s[best_from * g], c.t_s[std::min(c.t_s.size(), (best_from + best_len) * g) - 1]};
    for (const auto& [name, values] : c.covariates) {
      const double r = Correlation(c.residual, values);
      if (std::isfinite(r)) u.correlates_with[name] = r;
    }
    out.push_back(std::move(u));
  }
  return out;
}

std::string UnexplainedText(const Unexplained& u) {
  std::vector<std::pair<std::string, double>> by_size(u.correlates_with.begin(), u.correlates_with.end());
  std::stable_sort(by_size.begin(), by_size.end(),
                   [](const auto& a, const auto& b) { return std::abs(a.second) > std::abs(b.second); });
  std::vector<std::string> moves;
  for (size_t i = 0; i < by_size.size(); ++i)
    moves.push_back(i == 0 ? fmt::format("{} (r = {:+.2f})", by_size[i].first, by_size[i].second)
                           : fmt::format("{} ({:+.2f})", by_size[i].first, by_size[i].second));
  return fmt::format("{} in run {}: residual RMS {:.1f}x the noise of its score-block means ({:.3g}), not white "
                     "(Ljung-Box p {:.2g}), largest over t = {:.0f}-{:.0f} s{}{}",
                     u.channel, u.run, u.rms_over_noise, u.noise, u.ljung_box_p, u.t_s.first, u.t_s.second,
                     moves.empty() ? "" : "; moves with ", fmt::join(moves, ", "));
}

}  // namespace rlg::diagnosis
