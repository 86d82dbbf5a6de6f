#include "compensation/evaluation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "compensation/model_compensator.h"
#include "model/allan.h"
#include "sim/errors.h"
#include "sim/stats.h"

namespace rlg::compensation {
namespace {

/// The stabilities before and after, at the averaging time asked for and at 100 s, each pair
/// side by side (model::BiasStabilityPair); returns the 100 s block means before and after.
std::array<std::vector<double>, 2> AddStabilities(const sim::Run& run, const std::vector<double>& before,
                                                  const std::vector<double>& compensated, double dt,
                                                  const EvaluationOptions& o, RunEvaluation& e) {
  using model::BelowSamplePeriod;
  const BelowSamplePeriod chosen = o.averaging_explicit ? BelowSamplePeriod::kRefuse : BelowSamplePeriod::kUseOneSample;
  std::array<std::vector<double>, 2> means_100s;
  try {
    const auto at_chosen = model::BiasStabilityPair(before, compensated, dt, o.averaging_s, chosen);
    const auto at_100s =
        model::BiasStabilityPair(before, compensated, dt, 100.0, BelowSamplePeriod::kUseOneSample, &means_100s);
    e.stability_before = at_chosen[0];
    e.stability_after = at_chosen[1];
    e.stability_100s_before = at_100s[0];
    e.stability_100s_after = at_100s[1];
  } catch (const InputError& err) {
    throw InputError(fmt::format("{}: {}", run.Where(), err.what()));
  }
  return means_100s;
}

/// The largest |mean| over block means.
double PeakAbs(const std::vector<double>& means) {
  double largest = 0.0;
  for (double mean : means) largest = std::max(largest, std::abs(mean));
  return largest;
}

/// The least-squares slope of y = alpha + beta x and its standard error (°/h per °C).
struct Trend {
  double slope = 0.0;
  double standard_error = INFINITY;  ///< INFINITY: no variation of x, no trend can be estimated
};

/// The trend of the 100 s means y on those of Ti, x. The residuals of 100 s means are still
/// correlated (bias instability wanders over hours): the white-noise standard error is widened
/// by the AR(1) factor sqrt((1 + rho) / (1 - rho)), rho the lag-1 autocorrelation of the
/// residuals (floored at 0).
Trend FitTrend(const std::vector<double>& x, const std::vector<double>& y) {
  const double mx = sim::Mean(x), my = sim::Mean(y);
  double sxx = 0.0, sxy = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  Trend trend;
  if (!(x.size() > 2 && sxx > 0.0)) return trend;
  trend.slope = sxy / sxx;
  std::vector<double> r(x.size());
  double ssr = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    r[i] = y[i] - my - trend.slope * (x[i] - mx);
    ssr += r[i] * r[i];
  }
  double c0 = 0.0, c1 = 0.0;
  for (size_t i = 0; i < r.size(); ++i) {
    c0 += r[i] * r[i];
    if (i > 0) c1 += r[i] * r[i - 1];
  }
  const double rho = std::clamp(c0 > 0.0 ? c1 / c0 : 0.0, 0.0, 0.95);
  trend.standard_error = std::sqrt(ssr / static_cast<double>(x.size() - 2) / sxx * (1.0 + rho) / (1.0 - rho));
  return trend;
}

/// The Allan deviation of `curve` at the octave nearest tau_s.
double AdevNear(const model::AllanCurve& curve, double tau_s) {
  double best = INFINITY, adev = 0.0;
  for (size_t i = 0; i < curve.tau_s.size(); ++i) {
    if (std::abs(std::log(curve.tau_s[i] / tau_s)) < best) {
      best = std::abs(std::log(curve.tau_s[i] / tau_s));
      adev = curve.adev[i];
    }
  }
  return adev;
}

/// The Allan curve and read-offs of the compensated bias, and the errors read off it: of a B0
/// window mean (Allan deviation at the window length, nearest octave) and of one 100 s mean.
void AddAllanErrors(const std::vector<double>& compensated, double dt, double b0_window_s, RunEvaluation& e) {
  // The octaves used: the read-offs' (9 clusters) and the nearest of the 3-cluster curve to each
  // error's time, which lies below twice that time (an octave at twice it or more is farther
  // than the one below; a tie takes the lower): on a 2 h run at 1 s, 10 of the 12 octaves.
  const double longest = 2.0 * std::max(b0_window_s, e.stability_100s_after.averaging_s);
  size_t points = 0;
  for (size_t m = 1; 3 * m <= compensated.size() && (9 * m <= compensated.size() || static_cast<double>(m) * dt < longest);
       m *= 2) {
    ++points;
  }
  const model::AllanCurve curve = model::OverlappingAllan(compensated, dt, 3, points);
  e.allan = model::WithMinClusters(curve, compensated.size(), 9);
  e.noise = model::ReadNoiseTerms(e.allan);
  e.b0_error_dph = AdevNear(curve, b0_window_s);
  e.error_100s_dph = AdevNear(curve, e.stability_100s_after.averaging_s);
}

/// The noise floor of the trend's standard error (see the header): sqrt(2) sigma_A(T/2) over
/// the difference of Ti's means over the two halves of `half` samples each, sigma_A extrapolated
/// to half the run with every term the measured curve allows (FitNoiseTerms, as the read-offs'
/// every_term): bias instability that a 2 h record does not resolve is still there, and the
/// read-offs' AIC subset leaves it out.
double TrendNoiseFloor(const std::vector<double>& Ti, size_t half, double dt, const model::NoiseReadOffs& noise) {
  const double t_half = static_cast<double>(half) * dt;
  const double avar = model::AllanVariance(noise.every_term, t_half);
  double first = 0.0, second = 0.0;
  for (size_t i = 0; i < half; ++i) first += Ti[i];
  for (size_t i = half; i < 2 * half; ++i) second += Ti[i];
  const double dT_halves = std::abs(second - first) / static_cast<double>(half);
  return dT_halves > 0.0 ? std::sqrt(2.0 * avar) / dT_halves : INFINITY;
}

}  // namespace

RunEvaluation EvaluateRun(const sim::Run& run, const std::vector<double>& compensated,
                          const model::Guo2006Coefficients& c, double averaging_s) {
  EvaluationOptions o;
  o.averaging_s = averaging_s;
  o.averaging_explicit = true;
  return EvaluateRun(run, compensated, c, o);
}

RunEvaluation EvaluateRun(const sim::Run& run, const std::vector<double>& compensated,
                          const model::Guo2006Coefficients& c, const EvaluationOptions& options) {
  EvaluationOptions o = options;
  o.trend_channel = c.pair[0];
  o.b0_window_s = c.b0_window_s;
  RunEvaluation e = EvaluateCompensated(run, compensated, o);
  e.outside_fitted_range = e.Ti0_C < c.t10_range_C[0] || e.Ti0_C > c.t10_range_C[1];
  return e;
}

RunEvaluation EvaluateRun(const sim::Run& run, const std::vector<double>& compensated, const model::FittedModel& m,
                          const EvaluationOptions& options) {
  if (const auto* c = std::get_if<model::Guo2006Coefficients>(&m)) return EvaluateRun(run, compensated, *c, options);
  EvaluationOptions o = options;
  o.trend_channel = model::ModelChannels(m).front();
  if (model::ModelB0Window(m) > 0.0) o.b0_window_s = model::ModelB0Window(m);
  RunEvaluation e = EvaluateCompensated(run, compensated, o);
  e.outside_fitted_range = SamplesOutsideFittedRange(m, run) > 0;
  return e;
}

RunEvaluation EvaluateCompensated(const sim::Run& run, const std::vector<double>& compensated,
                                  const EvaluationOptions& o) {
  RunEvaluation e;
  e.run = run.id;
  e.averaging_s = o.averaging_s;
  const auto& before = run.Column(o.bias_column);
  if (run.size() < 2) throw InputError(fmt::format("{}: {} sample(s), too few to evaluate", run.Where(), run.size()));
  if (compensated.size() != run.size()) {
    throw InputError(fmt::format("{}: {} compensated values for {} samples", run.Where(), compensated.size(), run.size()));
  }
  const double dt = e.sample_period_s = model::SamplePeriod(run.t_s);
  const std::array<double, 2> means = model::MeanPair(before, compensated);
  e.bias_before_dph = means[0];
  e.bias_after_dph = means[1];
  // The 100 s stabilities' block means give the peaks and the trend too.
  const std::array<std::vector<double>, 2> means_100s = AddStabilities(run, before, compensated, dt, o, e);
  const auto& Ti = run.Column(o.trend_channel);
  e.Ti0_C = Ti.front();
  const size_t m = e.stability_100s_after.samples_per_block;
  e.peak_abs_100s_before_dph = PeakAbs(means_100s[0]);
  e.peak_abs_100s_after_dph = PeakAbs(means_100s[1]);
  const Trend trend = FitTrend(model::BlockMeans(Ti, m), means_100s[1]);
  e.trend_dph_per_C = trend.slope;
  e.trend_stderr_dph_per_C = trend.standard_error;
  AddAllanErrors(compensated, dt, o.b0_window_s, e);
  const size_t half = run.size() / 2;
  if (half > 0) e.trend_stderr_dph_per_C = std::max(e.trend_stderr_dph_per_C, TrendNoiseFloor(Ti, half, dt, e.noise));
  return e;
}

nlohmann::json EvaluationJson(const RunEvaluation& e) {
  nlohmann::json j = {{"run", e.run},
                      {"bias_before_dph", e.bias_before_dph},
                      {"bias_after_dph", e.bias_after_dph},
                      {"stability_before_dph", e.stability_before.sigma},
                      {"stability_after_dph", e.stability_after.sigma},
                      {"stability_100s_before_dph", e.stability_100s_before.sigma},
                      {"stability_100s_after_dph", e.stability_100s_after.sigma},
                      {"sample_period_s", e.sample_period_s},
                      {"stability_averaging_s", e.stability_after.averaging_s},
                      {"stability_100s_averaging_s", e.stability_100s_after.averaging_s},
                      {"stability_blocks", e.stability_after.blocks},
                      {"stability_100s_blocks", e.stability_100s_after.blocks},
                      {"peak_abs_100s_before_dph", e.peak_abs_100s_before_dph},
                      {"peak_abs_100s_after_dph", e.peak_abs_100s_after_dph},
                      {"error_100s_dph", e.error_100s_dph},
                      {"trend_dph_per_C", e.trend_dph_per_C},
                      {"trend_stderr_dph_per_C", e.trend_stderr_dph_per_C},
                      {"b0_error_dph", e.b0_error_dph},
                      {"outside_fitted_range", e.outside_fitted_range}};
  model::AddNoiseTermsJson(e.noise, j);
  return j;
}

std::optional<double> CommonAveraging(const std::vector<RunEvaluation>& evaluations, bool hundred) {
  std::optional<double> common;
  for (const auto& e : evaluations) {
    const double t = hundred ? e.stability_100s_after.averaging_s : e.stability_after.averaging_s;
    if (common && std::abs(*common - t) > 1e-6 * t) return std::nullopt;  // same tolerance as Stability::adjusted
    if (!common) common = t;
  }
  return common;
}

}  // namespace rlg::compensation
