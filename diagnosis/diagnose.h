#pragma once
/// Diagnosis of measured data against a nominal gyro (docs/diagnosis.md): the interface and
/// the record it returns. Diagnose runs seven stages, each a function of the problem (built
/// once, never changed) and the model it is given:
///
///  1. prepare (network/problem.h): runs, held-out split, fit and score blocks, a logged ambient's
///     curve, noise levels, CVODE tolerances.
///  2. calibrate (network/calibrate.h): the nominal thermal network's knobs and each run's nuisances
///     by nonlinear least squares on the temperature channels (network/fit_thermal.h); the bias
///     physics, linear in its coefficients once the node temperatures are known, is fitted
///     with every bias evaluation (network/bias_design.h, statistics/bias_fit.h).
///  3. residual checks (network/residual_checks.h): Ljung-Box whiteness per channel and for the bias;
///     steps in the held-out bias residual.
///  4. thermal search (network/thermal_search.h): every thermal and sensor effect of the catalog on
///     every target, screened by a linearised score test, the best few refitted in full,
///     scored in sample and on held-out data; its threshold from a null bootstrap
///     (network/thermal_null.h).
///  5. bias search (network/bias_search.h): every bias effect on every target as a regressor of the
///     linear bias fit, scored the same way; its threshold from a null bootstrap (network/bias_null.h).
///  6. rank and accept (statistics/rank.h, network/accept.h): thermal causes before bias ones (they are upstream),
///     the best accepted only if significant; stages 4-6 repeat on the extended model up to
///     max_steps.
///  7. report (statistics/unexplained.h, report.h): held-out RMS before and after each step, the
///     compensated bias's stability, what the final model still misses.

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/network/calibration_summary.h"
#include "diagnosis/candidate.h"
#include "diagnosis/statistics/identifiability.h"
#include "diagnosis/options.h"
#include "diagnosis/statistics/steps.h"
#include "diagnosis/statistics/unexplained.h"
#include "sim/gyro.h"
#include "sim/trace.h"

namespace rlg::diagnosis {

struct Metrics {
  double bias_rms_dph = 0.0;                         ///< held-out, on score blocks
  std::map<std::string, double> temperature_rms_C;   ///< held-out, on score blocks
};

/// A candidate the data do not tell apart from the accepted one, or prefer to it only at an
/// implausible size: of its kind, significant, and either within 10 score points of it or a
/// stand-in (fitted outside the catalog's plausible range) that scored above it and was set
/// aside for it (statistics/rank.h). The step's notes list the same ones.
struct Tie {
  std::string cause;
  std::string target;
  /// Its score minus the accepted one's (information-criterion units; of two bias candidates,
  /// under one noise model: statistics/rank.h): within (-10, 10) for a
  /// tie the fit data cannot split (mostly below 0, above where a twin was preferred on held-out
  /// RMS or the step's leader was passed over one step ahead: DiagnoseOptions::lookahead), any
  /// size below for one the held-out data cannot split, any size above 0 for a stand-in set
  /// aside.
  double score_difference = 0.0;
  /// Fitted inside the catalog's plausible range (Effect::OutsidePlausibleRange empty).
  bool plausible = true;
  /// Its held-out gain minus the accepted one's (Candidate::heldout_gain, the same units).
  double heldout_difference = 0.0;
  /// The data do not tell it from the accepted candidate (statistics/rank.h, kTieBand): within
  /// the band in score, or the held-out data prefer the accepted one by less than the band.
  /// False for a stand-in set aside only for its size.
  bool ambiguous = false;
};

/// What accepting a thermal cause did to a calibration knob: its shift from nominal in prior
/// sds (KnobCalibration::shift_sigma) before the step and after the recalibration with it.
struct KnobShift {
  std::string name;
  double before_sigma = 0.0;
  double after_sigma = 0.0;
};

struct DiagnosisStep {
  Candidate accepted;
  /// The knobs this step moved by at least one prior sd, or that were or are beyond
  /// kPriorConflictSigma, in the calibration's order (empty for bias steps: they leave the
  /// thermal knobs as they are).
  std::vector<KnobShift> knob_shifts;
  /// The score the accepted candidate had to reach at this step: the thermal or the bias
  /// null bootstrap's threshold (information-criterion units).
  double threshold = 0.0;
  Metrics before, after;
  double compensated_stability_ratio = 1.0;
  std::vector<Candidate> candidates;  ///< the accepted one first, then the rest best first
  std::vector<Tie> ties;              ///< the candidates tied with it, and stand-ins set aside, in rank order
  std::vector<std::string> notes;
};

/// A parametric bootstrap that sets the score a candidate must reach (docs/diagnosis.md: correlated noise breaks naive significance).
/// Bias: each replicate is bias data made of the calibrated baseline's fitted bias plus the
/// gyro file's own noise (ARW, bias instability, quantization), block-averaged like the data;
/// its score is the best information-criterion gain of a bias candidate that also passes the
/// held-out test (a held-out gain above min_heldout_gain), -infinity where none does. Thermal: each replicate is
/// the residual the calibrated model leaves on data it made itself (each channel's white noise
/// and the error of the curve through a noisy logged ambient; NullThermalReplicates, network/thermal_null.h);
/// its score is the best thermal candidate's screening gain less k ln n. The threshold is
/// max(min_score, largest replicate score): with 40 replicates a null dataset beats it about
/// 2.5 % of the time. Without the data (no bias column) or with null_replicates = 0 no
/// replicate is drawn and the threshold is min_score.
struct NullBootstrap {
  double threshold = 0.0;                ///< score a candidate must reach (information-criterion units)
  std::vector<double> replicate_scores;  ///< per replicate, in the order drawn
  int replicates = 0;                    ///< how many were drawn: replicate_scores.size()
  /// Thermal: the replicates' statistic on the data itself (the best screening score), so that
  /// its rank among them can be read (uniform over nulls when the bootstrap is honest); NaN
  /// for the bias bootstrap and without replicates.
  double data_score = std::numeric_limits<double>::quiet_NaN();
};

/// One run's residuals at the fit-block resolution (block means), for the report.
struct ResidualTrace {
  std::string run;
  std::vector<double> t_s;  ///< block mid-times
  /// channel or "bias_dph" -> block means of the data
  std::map<std::string, std::vector<double>> measured;
  /// channel or "bias_dph" -> measured - simulated, by the calibrated nominal model (baseline)
  /// and by the extended one. Bias residuals are held-out ones, each run with its own offset.
  std::map<std::string, std::vector<double>> baseline, extended;
};

/// What a diagnosis without a thermal network leaves in the bias, whether or not it moves with the
/// temperature (without_network/unexplained.h): its verdict is an all-clear only when this is at the
/// noise (RmsOverNoise at most kAllClearRmsOverNoise), and otherwise says how large it is.
struct BiasLeft {
  double rms_dph = 0.0;    ///< held-out RMS of the final residual's score-block means (extended.bias_rms_dph)
  double noise_dph = 0.0;  ///< white noise of a score-block mean of the bias, pooled over the same blocks
  std::string covariate;   ///< what the residual moves with most (T1, dT1/dt, heating T1); empty: none defined
  double r = 0.0;          ///< its correlation with it
  double null_r = 0.0;     ///< the largest |r| of the unexplained test's noise replicates (0 without them)
  int replicates = 0;      ///< how many there were
  /// rms_dph / noise_dph; infinite when the noise is 0 (an exact curve) and something is left.
  double RmsOverNoise() const;
};

/// Above this many times the white noise of its score-block means, what a diagnosis without a
/// network leaves is never called noise: pure white noise over 20 or more score blocks stays
/// below 1.5 (statistics/unexplained.h), so 3 is far outside it, while a residual of 30 times the noise once
/// ended in an all-clear (a FOG-like log cut into its cycles, tests/diagnosis/diagnose_blind_logs.py).
inline constexpr double kAllClearRmsOverNoise = 3.0;

/// What both searches record (Diagnose's and DiagnoseWithoutNetwork's): the steps accepted, the
/// candidates of the first search, the evidence they were judged by, and what is left.
struct SearchRecord {
  bool has_bias = false;
  /// Shortest and longest score block of the runs as computed (whole samples; equal for
  /// uniformly sampled data): the averaging time of every RMS and score in the report.
  std::pair<double, double> score_block_s{0.0, 0.0};
  Metrics baseline, extended;
  std::vector<DiagnosisStep> steps;          ///< accepted steps
  std::vector<Candidate> first_candidates;   ///< every candidate of the first search, in Rank's order
  /// How many of first_candidates are significant (statistics/rank.h): they lead the ranking,
  /// the rest follow by score.
  size_t first_significant = 0;
  std::map<std::string, double> ljung_box_p; ///< baseline residual whiteness per channel
  /// Per scored run, the largest step of the baseline's held-out bias residual where its
  /// statistic exceeds its threshold (diagnosis::LargestStep); empty without bias data.
  std::vector<DetectedStep> detected_steps;
  NullBootstrap null_bootstrap;               ///< the bias candidates' acceptance score and its replicates
  /// The thermal candidates' acceptance score of the first search and its replicates (each step
  /// draws its own against its own model: DiagnosisStep::threshold); without a network, no
  /// replicates and min_score.
  NullBootstrap thermal_null_bootstrap;
  /// Channels and runs the final model still misses by well over the noise, not white
  /// (statistics/unexplained.h); empty when its residuals are at the noise level.
  std::vector<diagnosis::Unexplained> unexplained;
  std::vector<std::string> notes;
  std::vector<ResidualTrace> residuals;
};

/// The power probability every EffectPower is computed at.
inline constexpr double kPowerLevel = 0.9;

/// How large one candidate must be for the first search to detect it, and to name it, with
/// probability kPowerLevel (statistics/power.h; docs/diagnosis.md, "Power"): linearised at the
/// calibrated nominal, its signature prewhitened as its score is (a thermal or sensor effect:
/// by each channel's AR model of the calibrated residuals, less what the knobs take up; a bias
/// effect: by the AR model of the baseline bias fit's residuals, less what the baseline's
/// columns take up), against the threshold the first search's null bootstrap of its kind set.
/// Sizes are magnitudes of `parameter`, the effect's size; infinite where no size reaches the
/// power (the calibration takes the whole signature, or a rival of its kind is its twin).
struct EffectPower {
  std::string cause, target;
  std::string parameter;         ///< the effect's size parameter
  double start = 0.0;            ///< its value where the signature was simulated
  /// Every parameter where the signature was simulated: the start, or for an effect with a
  /// positive shape parameter (a missing mass's capacity) the screen's variant where it shows most.
  std::map<std::string, double> at;
  double lambda_at_start = 0.0;  ///< noncentrality at `start`, after the knobs
  double detected = 0.0;         ///< size detected with probability kPowerLevel
  /// Size detected and named before every other candidate with probability at least
  /// kPowerLevel (the union bound of statistics/power.h; >= detected).
  double named = 0.0;
  std::string rival_cause, rival_target;  ///< the candidate of its kind of nearest signature (none: empty)
  double rival_cosine = 0.0;               ///< cosine of the two signatures after the knobs
  /// The size lies inside the catalog's plausible range of the parameter (either sign, the other
  /// parameters as in `at`). A size beyond it is fitted as a stand-in, which the ranking puts
  /// after every plausible cause (statistics/rank.h): named there, if at all, only when no
  /// plausible candidate is significant, so the 90 % does not hold for it.
  bool detected_plausible = true, named_plausible = true;
};

/// A diagnosis against a gyro (Diagnose): the search record and the calibrated network.
struct Diagnosis : SearchRecord {
  std::map<std::string, double> calibrated;  ///< knob name -> value (physical units)
  CalibrationSummary calibration;            ///< the baseline calibration: knobs, shifts, covariance, cost
  Identifiability identifiability;           ///< knob combinations the data determine or leave to the prior
  /// Posterior correlations of the calibrated knobs (log units) given their common scale, in
  /// the order of `knob_names`, within [-1, 1]; NaN for a knob that is (to round-off) the
  /// scale itself; empty with fewer than two knobs.
  std::vector<std::string> knob_names;
  Eigen::MatrixXd knob_correlations;
  /// The calibrated gyro with every accepted effect: the model the diagnosis scored.
  sim::GyroConfig extended_gyro;
  /// With DiagnoseOptions::power: per candidate of the first search, its linearised power:
  /// the thermal and sensor candidates in the catalog's order (each effect on its targets, the
  /// sensor effects channel by channel), then, with bias data, the bias candidates in theirs;
  /// empty otherwise.
  std::vector<EffectPower> power;
};

/// A diagnosis without a thermal network (DiagnoseWithoutNetwork): the search record, the
/// baseline polynomial that stands in for a calibrated nominal, and what is left in the bias.
struct DiagnosisWithoutNetwork : SearchRecord {
  int polynomial_order = 0;        ///< of the baseline polynomial
  std::string polynomial_channel;  ///< its temperature channel
  /// What the final model leaves in the bias (always set by DiagnoseWithoutNetwork; a record
  /// made otherwise may lack it).
  std::optional<BiasLeft> bias_left;
};

/// Runs the diagnosis. InputError for invalid options and for data that does not fit the gyro
/// (no matching channel, a data-driven source without its P_<name>_W column); NumericalError
/// when the baseline calibration is not usable (the nominal cannot be simulated on the data).
Diagnosis Diagnose(const sim::Trace& data, const sim::GyroConfig& nominal, const DiagnoseOptions& options);

/// A diagnosis without a thermal network (docs/diagnosis.md, "Without a thermal network"): data
/// with measured temperatures and a bias, and no gyro file. The bias search alone, over the
/// measured channels: the baseline is the best polynomial in the bias-temperature channel
/// (without_network/baseline.h); the candidates are the catalog's bias effects computed from tracks and
/// the model family's lag and hysteresis terms (without_network/candidates.h), scored like the bias
/// candidates of Diagnose (without_network/search.h) against the score a parametric bootstrap of the
/// baseline's residuals reaches (without_network/null.h), ranked by score (statistics/rank.h) and accepted up to
/// max_steps; then what stays (without_network/unexplained.h). The record has no thermal metrics, no
/// calibration and no extended gyro. InputError for invalid options or data without a bias or a
/// temperature channel (without_network/problem.h); NumericalError when no polynomial can be fitted.
DiagnosisWithoutNetwork DiagnoseWithoutNetwork(const sim::Trace& data, const DiagnoseOptions& options);

/// Stages 1 and 2 alone: data preparation and the baseline calibration of `nominal` to `data`, as
/// Diagnose does it before any search (Diagnosis::calibration). Same errors as Diagnose.
CalibrationSummary Calibrate(const sim::Trace& data, const sim::GyroConfig& nominal, const DiagnoseOptions& options);

/// Canonical form of an effect target for comparisons: nodes for channels, pairs sorted.
std::string CanonicalTarget(const sim::GyroConfig& gyro, const std::string& effect, const std::string& target);

}  // namespace rlg::diagnosis
