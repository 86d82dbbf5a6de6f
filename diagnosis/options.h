#pragma once
/// The options of a diagnosis (diagnose.h), each with its IsValid.

#include <functional>
#include <string>
#include <vector>

#include "diagnosis/statistics/unexplained.h"

namespace rlg::diagnosis {

/// The thermal least-squares fits (network/fit_thermal.h): the baseline calibration (network/calibrate.h), the
/// candidates' refits and the recalibration of an accepted thermal cause.
struct CalibrationOptions {
  /// Levenberg-Marquardt iterations of each of the two passes over the fit runs.
  int max_iterations = 50;
  /// Iterations of the held-out runs' nuisance fit (the knobs fixed; one or two unknowns per
  /// run, which converge in a few).
  int nuisance_max_iterations = 20;
  /// Ceres' relative cost decrease at which a pass stops. (Stopping instead once an accepted
  /// step gains less than 0.01 in chi^2, even three in a row, took ~15 % off a diagnosis but
  /// left a radiation refit 0.5 below its optimum, moved TCLab's calibrated convection by 0.1
  /// prior sd and a screening score by 10, and misnamed a blind 1 s case: the fits still walk
  /// flat valleys in small steps that add up.)
  double function_tolerance = 1e-8;
  /// Relative step of the forward differences. With CVODE's tolerances matched to the data
  /// (SolverForData) the differences stay clean at 1e-6; a 1e-4 step made CVODE change its
  /// step sequence between the two evaluations, which turned radiation's derivative into noise.
  double relative_step = 1e-6;

  /// False with a reason in *error (may be null) for iterations below 1, a tolerance outside
  /// (0, 1) or a step outside (0, 0.1].
  bool IsValid(std::string* error) const;
};

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
  /// Also compute the first search's linearised power at the calibrated nominal
  /// (Diagnosis::power, docs/diagnosis.md "Power"): one simulation per thermal or sensor
  /// candidate, the bias candidates' by linear algebra. Needs the first search, so max_steps
  /// of at least 1.
  bool power = false;
  /// Residual means for scores and RMS; taken in whole fit blocks, so the length used
  /// (Diagnosis::score_block_s) is the nearest whole number of them (99 s on 3 s data).
  double score_block_s = 100.0;
  /// Resolution of the thermal and bias fits (block means), in whole samples (at least one).
  double fit_block_s = 10.0;
  /// Held-out evidence needed to accept an effect with a thermal network: its held-out
  /// log-likelihood ratio (Candidate::heldout_gain, information units; bias residuals
  /// prewhitened by the candidate's autoregressive noise model) must exceed this. 0: the extension must
  /// predict the data it was not fitted on better, nothing more; the false-alarm rate is the
  /// null bootstraps' (null_replicates), which apply the same test.
  double min_heldout_gain = 0.0;
  /// Held-out RMS ratio needed to accept a term without a thermal network (the polynomial
  /// family over the measured temperatures; its residuals are not prewhitened, and bias
  /// instability makes in-sample gains of a few percent common on null data).
  double min_heldout_ratio = 1.05;
  double min_score = 10.0;       ///< information-criterion gain needed to accept
  /// Candidates this close to the best score are exact twins (a rate and the gradient it is),
  /// ranked by held-out RMS, then plausibility; anything further apart is ranked by score.
  double tie_score = 1e-6;
  /// Null replicates (calibrated model + the gyro's noise) that set the bias candidates'
  /// acceptance score; 0 = the information criterion's min_score alone.
  int null_replicates = 40;
  int thermal_refits = 4;        ///< screened thermal candidates refitted in full
  /// Thermal candidates compared one step ahead where they tie in score (within kTieBand of the
  /// leader, statistics/rank.h) and another step may follow: each is accepted in turn and the
  /// next step searched after it; the one whose score plus the score of the thermal candidate
  /// that next step would accept is largest is taken (docs/diagnosis.md, "The method": looking
  /// one step ahead). 1: the leader alone. Without a gyro file (no thermal search) unused.
  int lookahead = 2;
  CalibrationOptions calibration;  ///< the baseline calibration (stage 2, network/calibrate.h)
  UnexplainedOptions unexplained;  ///< what counts as left unexplained (stage 7, statistics/unexplained.h)
  /// Called with a one-line description as each stage or candidate refit starts ("step 1:
  /// refitting thermal candidate 2 of 4, thermal.missing_link block-case"); may be empty.
  /// The CLI prints it on stderr when stderr is a terminal (docs/cli.md). It must not
  /// throw; the diagnosis's result does not depend on it.
  std::function<void(const std::string&)> progress;

  /// False with a reason in *error (may be null): max_steps below 0, single_run_pieces below
  /// 2, block lengths not positive or a score block shorter than a fit block, held-out ratios
  /// below 1, a negative min_score or tie_score, negative replicates or refits, a lookahead
  /// below 1, or invalid calibration or unexplained options. Diagnose throws InputError with the reason.
  bool IsValid(std::string* error) const;
};

}  // namespace rlg::diagnosis
