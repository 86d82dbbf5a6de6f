#pragma once
/// Diagnosis of measured data against a nominal gyro (docs/diagnosis.md).
///
///  1. Calibrate: thermal knobs (log heat capacities, log conductances, log source gains,
///     per-run ambient when T_amb is absent) by nonlinear least squares (Ceres, Levenberg-
///     Marquardt, forward-difference Jacobians of the noise-free simulation) on the
///     temperature channels; then the bias physics, which is linear in its coefficients once
///     the node temperatures are known: per-run offsets, b1, b2, and for each Langmuir
///     gradient k and k c_T.
///  2. Residuals: per channel and for the bias, on block means; Ljung-Box whiteness; steps.
///  3. Name the cause: every catalog effect on every target it can act on. Thermal effects
///     come first (they are upstream of the bias): each is screened by a one-simulation
///     linearised (score) test, the best few are refitted in full. Bias effects add a
///     regressor (dT/dt, a gradient, heating increments, mode index). Each candidate is
///     scored on data not used for its fit (leave-one-run-out, the held-out runs, or the
///     held-out pieces of a single run) and by an information criterion on 100 s means
///     with an effective sample size from the residual autocorrelation. The best is accepted only if significant; the search
///     repeats on the extended model up to max_steps.
///  4. Gain: held-out RMS before/after each step and, for bias effects, the 100 s stability
///     of the compensated bias with and without the matching regressor.

#include <Eigen/Core>
#include <functional>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/calibration_summary.h"
#include "diagnosis/identifiability.h"
#include "diagnosis/steps.h"
#include "diagnosis/unexplained.h"
#include "sim/gyro.h"
#include "sim/trace.h"

namespace rlg::diagnosis {

struct DiagnoseOptions {
  int max_steps = 3;
  /// Runs the model is fitted on; the others are held out. Empty: all runs, scored by
  /// leave-one-run-out (bias) and two-fold cross-validation (thermal); a single run by
  /// held-out time.
  std::vector<std::string> fit_runs;
  /// With one run to fit and none held out, it is cut into this many equal pieces in time;
  /// the model is fitted on the even ones and scored on the odd ones.
  int single_run_pieces = 4;
  /// Each run has its own gain for every data-driven source, fitted like its ambient (a
  /// nuisance): runs from different boards of one design.
  bool per_run_source_gains = false;
  /// Residual means for scores and RMS; taken in whole fit blocks, so the length used
  /// (Diagnosis::score_block_s) is the nearest whole number of them (99 s on 3 s data).
  double score_block_s = 100.0;
  /// Resolution of the thermal and bias fits (block means), in whole samples (at least one).
  double fit_block_s = 10.0;
  /// Held-out gain needed to accept a bias effect: bias instability makes in-sample gains
  /// of a few percent common on null data.
  double min_heldout_ratio = 1.05;
  /// The same for thermal effects, whose residuals are white sensor noise.
  double min_heldout_ratio_thermal = 1.01;
  double min_score = 10.0;       ///< information-criterion gain needed to accept
  /// Candidates this close to the best score are exact twins (a rate and the gradient it is),
  /// ranked by held-out RMS, then plausibility; anything further apart is ranked by score.
  double tie_score = 1e-6;
  /// Null replicates (calibrated model + the gyro's noise) that set the bias candidates'
  /// acceptance score; 0 = the information criterion's min_score alone.
  int null_replicates = 40;
  int thermal_refits = 4;        ///< screened thermal candidates refitted in full
  CalibrationOptions calibration;  ///< the baseline calibration (stage 3)
  diagnosis::UnexplainedOptions unexplained;  ///< what counts as left unexplained (stage 6)
  /// Called with a one-line description as each stage or candidate refit starts ("step 1:
  /// refitting thermal candidate 2 of 4, thermal.missing_link block-case"); may be empty.
  /// The CLI prints it on stderr when stderr is a terminal (docs/cli.md). It must not
  /// throw; the diagnosis's result does not depend on it.
  std::function<void(const std::string&)> progress;

  /// False with a reason in *error (may be null): max_steps below 0, single_run_pieces below
  /// 2, block lengths not positive or a score block shorter than a fit block, held-out ratios
  /// below 1, a negative min_score or tie_score, negative replicates or refits, or invalid
  /// calibration or unexplained options. Diagnose throws InputError with the reason.
  bool IsValid(std::string* error) const;
};

struct Candidate {
  std::string cause;
  std::string target;
  std::map<std::string, double> parameters;
  double score = 0.0;
  double heldout_rms_ratio = 1.0;
  std::string kind;  ///< "thermal" or "bias"
  /// For a bias effect whose shape was searched on the data (a mode hop): where its term steps,
  /// as bias-node temperatures, which is what the data fix (empty otherwise).
  std::string shape_note;
};

struct Metrics {
  double bias_rms_dph = 0.0;                         ///< held-out, on score blocks
  std::map<std::string, double> temperature_rms_C;   ///< held-out, on score blocks
};

/// A candidate the data do not tell apart from the accepted one, or prefer to it only at an
/// implausible size: of its kind, significant, and either within 10 score points of it or a
/// stand-in (fitted outside the catalog's plausible range) that scored above it and was set
/// aside for it (diagnosis_rank.h). The step's notes list the same ones.
struct Tie {
  std::string cause;
  std::string target;
  /// Its score minus the accepted one's (information-criterion units): within (-10, 10) for a
  /// tie (mostly below 0, above where a twin was preferred on held-out RMS), any size above 0
  /// for a stand-in set aside.
  double score_difference = 0.0;
  /// Fitted inside the catalog's plausible range (Effect::OutsidePlausibleRange empty).
  bool plausible = true;
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
  std::vector<Candidate> candidates;  ///< best first
  std::vector<Tie> ties;              ///< the candidates tied with it, and stand-ins set aside, in rank order
  std::vector<std::string> notes;
};

/// A parametric bootstrap that sets the score a candidate must reach (docs/diagnosis.md: correlated noise breaks naive significance).
/// Bias: each replicate is bias data made of the calibrated baseline's fitted bias plus the
/// gyro file's own noise (ARW, bias instability, quantization), block-averaged like the data;
/// its score is the best information-criterion gain of a bias candidate that also passes the
/// held-out test (min_heldout_ratio), -infinity where none does. Thermal: each replicate is
/// the residual the calibrated model leaves on data it made itself (each channel's white noise
/// and the error of the curve through a noisy logged ambient; Engine::NullThermalReplicates);
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

struct Diagnosis {
  bool has_bias = false;
  /// Shortest and longest score block of the runs as computed (whole samples; equal for
  /// uniformly sampled data): the averaging time of every RMS and score in the report.
  std::pair<double, double> score_block_s{0.0, 0.0};
  Metrics baseline, extended;
  std::vector<DiagnosisStep> steps;          ///< accepted steps
  std::vector<Candidate> first_candidates;   ///< every candidate of the first search, best first
  std::map<std::string, double> calibrated;  ///< knob name -> value (physical units)
  CalibrationSummary calibration;            ///< the baseline calibration: knobs, shifts, covariance, cost
  Identifiability identifiability;           ///< knob combinations the data determine or leave to the prior
  /// Posterior correlations of the calibrated knobs (log units) given their common scale, in
  /// the order of `knob_names`, within [-1, 1]; NaN for a knob that is (to round-off) the
  /// scale itself; empty with fewer than two knobs.
  std::vector<std::string> knob_names;
  Eigen::MatrixXd knob_correlations;
  std::map<std::string, double> ljung_box_p; ///< baseline residual whiteness per channel
  /// Per scored run, the largest step of the baseline's held-out bias residual where its
  /// statistic exceeds its threshold (diagnosis::LargestStep); empty without bias data.
  std::vector<DetectedStep> detected_steps;
  NullBootstrap null_bootstrap;               ///< the bias candidates' acceptance score and its replicates
  /// The thermal candidates' acceptance score of the first search and its replicates (each step
  /// draws its own against its own model: DiagnosisStep::threshold).
  NullBootstrap thermal_null_bootstrap;
  /// Channels and runs the final model still misses by well over the noise, not white
  /// (diagnosis_unexplained.h); empty when its residuals are at the noise level.
  std::vector<diagnosis::Unexplained> unexplained;
  std::vector<std::string> notes;
  std::vector<ResidualTrace> residuals;
  sim::GyroConfig extended_gyro;
};

/// Runs the diagnosis. InputError for invalid options and for data that does not fit the gyro
/// (no matching channel, a data-driven source without its P_<name>_W column); NumericalError
/// when the baseline calibration is not usable (the nominal cannot be simulated on the data).
Diagnosis Diagnose(const sim::Trace& data, const sim::GyroConfig& nominal, const DiagnoseOptions& options);

/// Stage 3 alone: data preparation and the baseline calibration of `nominal` to `data`, as
/// Diagnose does it before any search (Diagnosis::calibration). Same errors as Diagnose.
CalibrationSummary Calibrate(const sim::Trace& data, const sim::GyroConfig& nominal, const DiagnoseOptions& options);

/// Canonical form of an effect target for comparisons: nodes for channels, pairs sorted.
std::string CanonicalTarget(const sim::GyroConfig& gyro, const std::string& effect, const std::string& target);

}  // namespace rlg::diagnosis
