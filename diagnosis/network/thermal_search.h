#pragma once
/// Stage 4 of a diagnosis: the thermal search. Every thermal and sensor effect of the catalog on
/// every target the model does not already hold is a candidate:
///
///  1. screening (statistics/screen.h): each candidate, at its start size (and a positive shape parameter
///     also a decade either side), by a linearised score test against the calibrated knobs'
///     Jacobian J0: credited only for what recalibrating the knobs could not explain; its
///     screening gain, step and, with the null bootstrap, each replicate's gain;
///  2. choosing refits: the best thermal_refits by screening gain, those with a gain above 0;
///     the rest are reported as screened only (kind kThermalScreened, score gain - ln n);
///  3. multistart refit: the effect's size scaled by the screening step, its start searched on
///     a log-space grid (statistics/multistart.h) with the knobs profiled out to first order, a knob step,
///     then a fit of the effect alone and one jointly with every knob (FitThermal); while a
///     knob of the model is in conflict with its prior (KnobsInConflict), also from the nominal
///     knobs, and the better end point by chi² + the knobs' prior is kept;
///  4. scoring: the log-likelihood ratio of the prewhitened residuals (ThermalGlsGain, each
///     channel's AR model the candidate's) plus the knobs' prior's change (KnobPriorCost) less
///     k ln n, k the reported parameters and n the fit residuals; the held-out gain of the
///     effect fitted on other runs or other times predicting the rest (or the held-out runs); kind
///     kThermalNoEffect where the fitted effect, taken out again, moves the prediction by less
///     than min_score (in noise units, chi²).
///
/// The threshold a candidate must reach comes from the thermal null bootstrap (network/thermal_null.h),
/// whose replicates are screened with the data.

#include <vector>

#include "diagnosis/network/calibrate.h"
#include "diagnosis/candidate.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/network/free.h"
#include "diagnosis/network/model.h"
#include "diagnosis/network/prediction.h"
#include "diagnosis/network/problem.h"
#include "diagnosis/progress.h"

namespace rlg::diagnosis {

struct ThermalSearch {
  /// Best screening gain first; a candidate whose refit could not start from any start is left
  /// out.
  std::vector<Candidate> candidates;
  /// Per candidate, the model with it refitted (the searched model itself for one screened
  /// only).
  std::vector<Model> models;
  /// With the null bootstrap: its replicates' best screening scores and the threshold.
  NullBootstrap null;
};

/// The thermal search of model m (pred: its prediction on every run; channel_var: the
/// channels' weights in its fits), with the thermal null bootstrap when `with_null` and
/// options.null_replicates > 0. A refitted candidate's score is ThermalGlsGain against m, the
/// AR orders those of m's residuals, plus the knob priors' change, less k ln n.
ThermalSearch SearchThermal(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                            const std::vector<double>& channel_var, bool with_null, const Progress& progress);

/// The linearised power of the thermal search on model m (pred: its prediction on every run)
/// against the acceptance score `threshold` (Diagnosis::power, statistics/power.h): every
/// candidate SearchThermal would screen, at its start (and, as the screen, a positive shape
/// parameter a decade either side, the variant of most noncentrality kept); its signature
/// prewhitened by each channel's AR model of m's residuals (ThermalNoiseModels, the orders
/// of ThermalArOrders), its noncentrality after the knobs (|p|² of the score test on the
/// prewhitened knob Jacobian), the sizes detected and named with probability kPowerLevel,
/// and the candidate of nearest signature. One simulation per candidate and variant.
std::vector<EffectPower> ThermalPower(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                                      const std::vector<double>& channel_var, double threshold);

/// The search on a calibration, as the diagnosis's first step makes it, without the null
/// bootstrap: its candidates.
std::vector<Candidate> FirstThermalCandidates(const Problem& p, const Calibration& cal);

/// The effect model.effects[e] with its free parameters `effect_free` moved to the best start
/// for its local refit: the current values or a point of a log-space grid over each positive
/// parameter's plausible range (statistics/multistart.h), by chi² on the fit runs plus the parameters'
/// priors, the baseline knobs held; or, given `chi2`, by chi2(trial) plus the priors (the
/// knobs profiled out).
Model SearchEffectStart(const Problem& p, const Model& model, int e, const std::vector<Free>& effect_free,
                        const std::vector<double>& channel_var,
                        const std::function<double(const Model&)>& chi2 = nullptr);

}  // namespace rlg::diagnosis
