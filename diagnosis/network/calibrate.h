#pragma once
/// Stage 2 of a diagnosis: calibration of the nominal thermal network to the data
/// (docs/diagnosis.md): the baseline decides everything that follows.
///
/// The knobs x (log heat capacities, log conductances, log radiating areas, log source gains)
/// and the per-run nuisances (an unlogged ambient, per-run heater gains, the start where the
/// ambient is logged with noise) minimise
///     1/2 sum_runs sum_channels sum_blocks ((T_sim - T_meas) / sigma_channel)²
///       + 1/2 sum_knobs ((x_i - ln nominal_i) / s)²
///       + 1/2 sum_runs (start_r / sd_r)² + 1/2 sum_gains ((ln g - 0) / s)²
/// (sd_r the standard error of run r's ambient curve at its first sample) by FitThermal, s the
/// gyro file's relative uncertainty. sigma_channel comes from a first pass with unit weights
/// (the residual RMS of each channel, floored at 0.5 mK); the fit is then repeated with it,
/// and the held-out runs' nuisances are fitted with the knobs fixed. The knobs' posterior
/// covariance is (J^T J)^+ of the weighted residuals and prior rows at the optimum.
///
/// A fit that ends with a knob in conflict with its prior (KnobsInConflict) and misses the
/// data by well over their noise (a channel's residual variance above twice its white
/// noise's, or of the variances' floor) is repeated from the common factor on every heat
/// capacity (0.5-2, a grid of 2^(i/6)) that fits the fit runs best, unweighted; the likelier
/// of the two calibrations (CalibrationDeviance) is kept.

#include <vector>

#include "diagnosis/network/calibration_summary.h"
#include "diagnosis/network/model.h"
#include "diagnosis/network/problem.h"

namespace rlg::diagnosis {

/// The calibrated baseline model, the channel variances it weighs residuals with (°C², per
/// gyro sensor), and its summary.
struct Calibration {
  Model model;
  std::vector<double> channel_var;
  CalibrationSummary summary;
};

/// The calibration above from the model `start` (NominalModel). NumericalError when the fit
/// cannot start (the nominal cannot be simulated on the data).
Calibration Calibrate(const Problem& p, const Model& start);

/// The three passes above from `start` alone, without the restart. NumericalError as Calibrate.
Calibration CalibrateOnce(const Problem& p, const Model& start);

/// -2 ln L of a calibration on the fit runs up to a constant: sum over channels of n ln var
/// (its residuals' own variance) + the weighted chi² + the knobs' prior. Two fits with
/// different channel variances compare by it, not by their costs.
double CalibrationDeviance(const Problem& p, const Calibration& c);

}  // namespace rlg::diagnosis
