#pragma once
/// Fits a polynomial model with its extra terms (model/poly_model.h) to runs of the tidy CSV:
/// the range [T_min, T_max] and (by default) T_ref = (T_min + T_max) / 2 from the training
/// samples, the regressors of every training sample from each run's power-on, one linear least
/// squares with cluster-robust errors (model/linear_fit.h). A lag's tau and a hysteresis width
/// w are fitted by a profile search (model/profile_search.h) of the linear fit's residual sum
/// of squares, every linear coefficient solved at each trial (variable projection): w over
/// [span / 200, span / 2] (span = T_max - T_min), tau over [2 sample periods, half the longest
/// run]. With both, the grid is every pair of their grid points (16 x 16: a lag can take the
/// place of a hysteresis or a gradient in part, so one search at a time would depend on where
/// it started), then three rounds of a golden-section search of each between its grid
/// neighbours, the other held. The linear coefficients' errors are those at the fitted
/// tau and w (conditional on them).
///
/// The rate term's tau_r is not fitted: RateTau, ten sample periods (the median time step of
/// the training runs), unless given. A first-order low-pass over ten samples passes rates that
/// change over minutes (its group delay is tau_r) and lowers the white noise of a backward
/// difference by sqrt(2 tau_r / dt) = 4.5: a sensor quantised to 0.01 °C and sampled at 1 s
/// reads 0.25 °C/min of noise unfiltered, 0.05 °C/min filtered.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "model/b0_window.h"
#include "model/linear_fit.h"
#include "model/poly_model.h"
#include "model/profile_search.h"
#include "sim/trace.h"

namespace rlg::model {

struct PolyFitOptions {
  std::string channel = "T1";
  int order = 3;                             ///< 1..5
  OffsetRule offset = OffsetRule::kFitted;
  std::optional<double> reference_C;         ///< T_ref; default the middle of the fitted span
  /// Extra terms: "rate", "hysteresis", "lag", "gradient:Tj", "gradient" for one term per
  /// other temperature channel the runs share (T1, T2, ..., T_name; not T_amb), or a product
  /// such as "T1*(T2-T1)" (model/poly_model.h, ParseTerm).
  std::vector<std::string> terms;
  bool extrapolate = false;                  ///< beyond the fitted range: hold (false) or extrapolate
  double b0_window_s = kB0Window_s;                ///< power_on: B0's window
  double rate_tau_s = 0.0;                   ///< the rate term's tau_r; 0: RateTau
  PolyPreset preset = PolyPreset::kPoly;     ///< written to the file
  LinearFitOptions linear;
  ProfileOptions profile;
  bool IsValid(std::string* error) const;
};

/// The presets of the header of model/poly_model.h: px4 and ardupilot (channel T1);
/// InputError for another.
PolyFitOptions PresetOptions(PolyPreset preset);

/// tau_r of the rate term for data sampled every `sample_period_s`: ten sample periods.
double RateTau(double sample_period_s);

/// Whether `channel` heats and cools by at least `w` (°C) on the samples `mask` keeps: a play
/// operator w wide is pushed up ({true, ..}) and down ({.., true}) (the hysteresis term's need).
std::array<bool, 2> HeatsAndCools(const std::vector<const sim::Run*>& runs, const RowMask& mask,
                                  const std::string& channel, double w);

/// The fit on the samples of `runs` that `mask` keeps (every sample when empty). InputError for
/// invalid options, a missing channel or bias, a power-on run shorter than the B0 window, a
/// term named twice, a gradient to the channel itself; NumericalError when the data cannot
/// identify the coefficients: a channel that does not move, a hysteresis term without heating
/// and cooling of at least a tenth of the span, an ill-conditioned fit (naming the
/// coefficients and what data would separate them).
PolyModel FitPoly(const std::vector<const sim::Run*>& runs, const PolyFitOptions& options, const RowMask& mask = {});

}  // namespace rlg::model
