#include "compensation/evaluation.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "compensation/model_compensator.h"
#include "model/allan.h"
#include "sim/errors.h"
#include "sim/stats.h"

namespace rlg::compensation {

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
  e.bias_before_dph = sim::Mean(before);
  e.bias_after_dph = sim::Mean(compensated);
  using model::BelowSamplePeriod;
  const BelowSamplePeriod chosen = o.averaging_explicit ? BelowSamplePeriod::kRefuse : BelowSamplePeriod::kUseOneSample;
  try {
    e.stability_before = model::BiasStability(before, dt, o.averaging_s, chosen);
    e.stability_after = model::BiasStability(compensated, dt, o.averaging_s, chosen);
    e.stability_100s_before = model::BiasStability(before, dt, 100.0, BelowSamplePeriod::kUseOneSample);
    e.stability_100s_after = model::BiasStability(compensated, dt, 100.0, BelowSamplePeriod::kUseOneSample);
  } catch (const InputError& err) {
    throw InputError(fmt::format("{}: {}", run.Where(), err.what()));
  }
  const auto& Ti = run.Column(o.trend_channel);
  e.Ti0_C = Ti.front();
  // The peaks over the blocks of the 100 s stability (a trailing partial block left out, as there).
  auto peak = [&](const std::vector<double>& y) {
    const size_t m = e.stability_100s_after.samples_per_block;
    double largest = 0.0;
    for (size_t b = 0; (b + 1) * m <= y.size(); ++b) {
      double sum = 0.0;
      for (size_t i = b * m; i < (b + 1) * m; ++i) sum += y[i];
      largest = std::max(largest, std::abs(sum / static_cast<double>(m)));
    }
    return largest;
  };
  e.peak_abs_100s_before_dph = peak(before);
  e.peak_abs_100s_after_dph = peak(compensated);

  // Trend on 100 s means (whole samples, as the 100 s stability): y = alpha + beta T.
  const size_t m = e.stability_100s_after.samples_per_block;
  std::vector<double> x, y;
  for (size_t b = 0; (b + 1) * m <= run.size(); ++b) {
    double sx = 0.0, sy = 0.0;
    for (size_t i = b * m; i < (b + 1) * m; ++i) {
      sx += Ti[i];
      sy += compensated[i];
    }
    x.push_back(sx / static_cast<double>(m));
    y.push_back(sy / static_cast<double>(m));
  }
  const double mx = sim::Mean(x), my = sim::Mean(y);
  double sxx = 0.0, sxy = 0.0;
  for (size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (y[i] - my);
  }
  if (x.size() > 2 && sxx > 0.0) {
    e.trend_dph_per_C = sxy / sxx;
    double ssr = 0.0;
    for (size_t i = 0; i < x.size(); ++i) {
      const double r = y[i] - my - e.trend_dph_per_C * (x[i] - mx);
      ssr += r * r;
    }
    // The residuals of 100 s means are still correlated (bias instability wanders over hours):
    // widen the white-noise standard error by the AR(1) factor sqrt((1 + rho) / (1 - rho)),
    // rho the lag-1 autocorrelation of the residuals (floored at 0).
    std::vector<double> r(x.size());
    for (size_t i = 0; i < x.size(); ++i) r[i] = y[i] - my - e.trend_dph_per_C * (x[i] - mx);
    double c0 = 0.0, c1 = 0.0;
    for (size_t i = 0; i < r.size(); ++i) {
      c0 += r[i] * r[i];
      if (i > 0) c1 += r[i] * r[i - 1];
    }
    const double rho = std::clamp(c0 > 0.0 ? c1 / c0 : 0.0, 0.0, 0.95);
    e.trend_stderr_dph_per_C = std::sqrt(ssr / static_cast<double>(x.size() - 2) / sxx * (1.0 + rho) / (1.0 - rho));
  } else {
    e.trend_stderr_dph_per_C = INFINITY;  // no temperature variation: no trend can be estimated
  }

  // Error of a B0-window mean: Allan deviation at the window length (nearest octave).
  const model::AllanCurve curve = model::OverlappingAllan(compensated, dt, 3);
  e.allan = model::OverlappingAllan(compensated, dt);
  e.noise = model::ReadNoiseTerms(e.allan);
  auto adev_near = [&](double tau_s) {
    double best = INFINITY, adev = 0.0;
    for (size_t i = 0; i < curve.tau_s.size(); ++i) {
      if (std::abs(std::log(curve.tau_s[i] / tau_s)) < best) {
        best = std::abs(std::log(curve.tau_s[i] / tau_s));
        adev = curve.adev[i];
      }
    }
    return adev;
  };
  e.b0_error_dph = adev_near(o.b0_window_s);
  e.error_100s_dph = adev_near(e.stability_100s_after.averaging_s);
  // Noise floor of the trend's standard error (see the header), extrapolated to half the run
  // with every term the measured curve allows (FitNoiseTerms): bias instability that a 2 h
  // record does not resolve is still there, and the read-offs' AIC subset leaves it out.
  const size_t half = run.size() / 2;
  if (half > 0) {
    const double t_half = static_cast<double>(half) * dt;
    const double avar = model::AllanVariance(model::FitNoiseTerms(e.allan), t_half);
    double first = 0.0, second = 0.0;
    for (size_t i = 0; i < half; ++i) first += Ti[i];
    for (size_t i = half; i < 2 * half; ++i) second += Ti[i];
    const double dT_halves = std::abs(second - first) / static_cast<double>(half);
    const double floor = dT_halves > 0.0 ? std::sqrt(2.0 * avar) / dT_halves : INFINITY;
    e.trend_stderr_dph_per_C = std::max(e.trend_stderr_dph_per_C, floor);
  }
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
