#pragma once
/// Before/after evaluation of a compensated run: the paper's Table 2 analogue.
///   bias       run mean (°/h)
///   stability  1 sigma of consecutive means over an averaging time (model::BiasStability),
///              at the chosen time (1 s by default: the reading of Table 2 that makes its two
///              columns consistent, docs/physics.md) and at 100 s (the laser-gyro convention).
///              Both over whole samples of the run's sample period (the median time step):
///              each Stability carries the time it was really computed at. A time shorter than
///              one sample is refused when the user chose it, and raised to one sample when it
///              is a default (1 s, 100 s) meeting coarser data.
///   trend      least-squares slope of the compensated bias against Ti, on 100 s means. Its
///              standard error is the larger of the OLS error widened for lag-1
///              autocorrelation (AR(1)) and the noise floor of any slope over the run:
///              sqrt(2) sigma_A(T/2) / (mean Ti of the second half - of the first half), with
///              sigma_A from the fitted Allan terms of the compensated bias. Bias instability
///              wanders over hours like a trend would; the floor keeps it from being called one.
///   B0 error   the 1 sigma error of a B0 window mean, read as the Allan deviation of the
///              compensated bias at the window length: the floor for |bias after|
///   peak       the largest |mean| over the 100 s blocks of the 100 s stability (whole samples,
///              consecutive from the first): a run mean can be ~0 while the compensated bias
///              drifts from -x to +x over the run, as it does on ramps; the peak shows it
///   100 s error the 1 sigma error of one 100 s mean, read as the Allan deviation of the
///              compensated bias at 100 s (the nearest octave of the curve, as the B0 error)

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "model/allan.h"
#include "model/b0_window.h"
#include "model/compensation_model.h"
#include "model/guo2006.h"
#include "sim/trace.h"

namespace rlg::compensation {

struct EvaluationOptions {
  /// Averaging time (s) of the first pair of stability columns.
  double averaging_s = 1.0;
  /// The user chose averaging_s (a flag, a suite key): below the sample period it is an error.
  /// Otherwise it is a default and is computed at one sample there, saying so.
  bool averaging_explicit = false;
  /// The raw bias column the "before" numbers are read from (°/h).
  std::string bias_column = "bias_dph";
  /// Ti: the channel the residual trend is regressed on and Ti0 read from. The overloads that
  /// take coefficients use the fit's (its pair's first channel) instead.
  std::string trend_channel = "T1";
  /// The B0 window (s) whose mean's error is read off (b0_error_dph). The overloads that take
  /// coefficients use the fit's instead.
  double b0_window_s = model::kB0Window_s;
};

struct RunEvaluation {
  std::string run;
  double sample_period_s = 0.0;  ///< median time step: what the averaging times are whole multiples of
  double averaging_s = 1.0;      ///< the averaging time asked for
  double bias_before_dph = 0.0;
  double bias_after_dph = 0.0;
  model::Stability stability_before, stability_after;            ///< at averaging_s (as computed)
  model::Stability stability_100s_before, stability_100s_after;  ///< at 100 s (as computed)
  double trend_dph_per_C = 0.0;
  double trend_stderr_dph_per_C = 0.0;
  double b0_error_dph = 0.0;
  double peak_abs_100s_before_dph = 0.0;  ///< largest |100 s mean| of the raw bias
  double peak_abs_100s_after_dph = 0.0;   ///< largest |100 s mean| of the compensated bias
  double error_100s_dph = 0.0;            ///< 1 sigma error of one 100 s mean (Allan deviation at ~100 s)
  model::AllanCurve allan;     ///< Allan deviation of the compensated bias (the curve `noise` is read from)
  model::NoiseReadOffs noise;  ///< Allan read-offs of the compensated bias
  double Ti0_C = 0.0;
  bool outside_fitted_range = false;  ///< Ti0 outside T10_range_C of the coefficients
};

RunEvaluation EvaluateRun(const sim::Run& run, const std::vector<double>& compensated,
                          const model::Guo2006Coefficients& coefficients, const EvaluationOptions& options = {});
/// The same for a compensated column made by any algorithm (no coefficients): the trend
/// against options.trend_channel, the B0 error at options.b0_window_s, no fitted range
/// (outside_fitted_range false). `compensated` has one value per sample of `run`.
RunEvaluation EvaluateCompensated(const sim::Run& run, const std::vector<double>& compensated,
                                  const EvaluationOptions& options = {});
/// The same for any model of the family (model/compensation_model.h): the trend against its
/// first channel, the B0 error at its B0 window (a power-on offset), and outside_fitted_range
/// where Eq. (2)'s Ti0 or any sample of a polynomial lies beyond its fitted range.
RunEvaluation EvaluateRun(const sim::Run& run, const std::vector<double>& compensated, const model::FittedModel& model,
                          const EvaluationOptions& options = {});
/// The same with an averaging time given explicitly.
RunEvaluation EvaluateRun(const sim::Run& run, const std::vector<double>& compensated,
                          const model::Guo2006Coefficients& coefficients, double averaging_s);

/// The per-run keys of `compensate --json` (docs/cli.md), plus: the averaging times the
/// stabilities were computed at (stability_averaging_s, stability_100s_averaging_s) and the
/// sample period, the number of block means each stability is the scatter of (stability_blocks,
/// stability_100s_blocks), the trend, the B0 error, the peaks of the 100 s means
/// (peak_abs_100s_before_dph, peak_abs_100s_after_dph) and the error of one 100 s mean
/// (error_100s_dph), and the Allan read-offs (model::AddNoiseTermsJson).
nlohmann::json EvaluationJson(const RunEvaluation& e);

/// The one averaging time (s) at which every evaluation's first stability (or, with hundred,
/// its 100 s one) was computed; nullopt when runs differ (mixed sample periods).
std::optional<double> CommonAveraging(const std::vector<RunEvaluation>& evaluations, bool hundred = false);

}  // namespace rlg::compensation
