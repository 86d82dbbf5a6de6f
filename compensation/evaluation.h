#pragma once
/// Before/after evaluation of a compensated run: the paper's Table 2 analogue.
///   bias       run mean (°/h)
///   stability  1 sigma of consecutive means over an averaging time (model::BiasStability),
///              at the chosen time (1 s by default: the reading of Table 2 that makes its two
///              columns consistent, PHYSICS.md) and at 100 s (the laser-gyro convention)
///   trend      least-squares slope of the compensated bias against Ti, on 100 s means. Its
///              standard error is the larger of the OLS error widened for lag-1
///              autocorrelation (AR(1)) and the noise floor of any slope over the run:
///              sqrt(2) sigma_A(T/2) / (mean Ti of the second half - of the first half), with
///              sigma_A from the fitted Allan terms of the compensated bias. Bias instability
///              wanders over hours like a trend would; the floor keeps it from being called one.
///   B0 error   the 1 sigma error of a B0 window mean, read as the Allan deviation of the
///              compensated bias at the window length: the floor for |bias after|

#include <string>
#include <vector>

#include "model/allan.h"
#include "model/guo2006.h"
#include "sim/trace.h"

namespace rlg::compensation {

struct RunEvaluation {
  std::string run;
  double averaging_s = 1.0;
  double bias_before_dph = 0.0;
  double bias_after_dph = 0.0;
  double stability_before_dph = 0.0;
  double stability_after_dph = 0.0;
  double stability_100s_before_dph = 0.0;
  double stability_100s_after_dph = 0.0;
  double trend_dph_per_C = 0.0;
  double trend_stderr_dph_per_C = 0.0;
  double b0_error_dph = 0.0;
  model::NoiseTerms noise;  ///< Allan read-offs of the compensated bias
  double Ti0_C = 0.0;
  bool outside_fitted_range = false;  ///< Ti0 outside T10_range_C of the coefficients
};

RunEvaluation EvaluateRun(const sim::Run& run, const std::vector<double>& compensated,
                          const model::Guo2006Coefficients& coefficients, double averaging_s = 1.0);

}  // namespace rlg::compensation
