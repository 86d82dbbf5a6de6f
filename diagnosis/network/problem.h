#pragma once
/// Stage 1 of a diagnosis: the problem, everything the later stages read and none of them
/// changes. MakeProblem builds it once from the data, the nominal gyro and the options:
///
///  - the runs prepared for fitting and scoring (data/prepare.h: PreparedRun), split into fit and
///    held-out runs (DiagnoseOptions::fit_runs; a single run with none held out cut in time
///    into its even and odd pieces, SplitInTime);
///  - the baseline knobs of the nominal gyro (network/model.h: BaselineKnobs);
///  - per run, its counted fit blocks (whole samples, BlockLayout), their mean sample times and
///    their BlockTimes, and a logged ambient's curve (LoggedAmbient) with its noise;
///  - the noise levels: of a score-block mean of the temperatures (ScoreBlockNoise, °C), of
///    a fit-block mean of the bias by the gyro file's noise terms (°/h), and the CVODE
///    tolerances that follow (SolverForData).
///
/// Every later stage is a function of (const Problem&, the model it is given): the problem
/// holds no model, and the current one is the caller's.

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/data/block_times.h"
#include "diagnosis/network/model.h"
#include "diagnosis/options.h"
#include "diagnosis/data/prepare.h"
#include "sim/gyro.h"
#include "sim/solver_options.h"
#include "sim/trace.h"

namespace rlg::diagnosis {

struct Problem {
  sim::GyroConfig nominal;
  DiagnoseOptions options;
  /// Each run's own gain for every data-driven source, fitted as a nuisance (Model::run_gain;
  /// options.per_run_source_gains).
  bool per_run_source_gains = false;
  /// The prepared runs, pointing into the data (which must outlive the problem); a single run
  /// held out in time is two: its fitted pieces (0) and its held-out ones (1).
  std::vector<PreparedRun> runs;
  std::vector<int> fit, held;  ///< indices into runs
  std::string split_note;      ///< how a single run was split in time, if it was
  std::vector<BaseKnob> knobs;
  int n_nodes = 0;                  ///< nodes of the nominal network
  bool has_bias = false;            ///< every run has a bias column
  bool has_logged_ambient = false;  ///< some run logs T_amb
  /// Per run, its counted fit blocks (samples [first, second)), their mean sample times (s)
  /// and their BlockTimes.
  std::vector<std::vector<std::pair<size_t, size_t>>> fit_blocks;
  std::vector<std::vector<double>> block_times;
  std::vector<std::vector<BlockTimes>> block_spans;
  /// Per run and sensor of the nominal, BlockMeans of its measured column (°C; empty where the
  /// run has no such column): what every thermal residual is taken against, made once.
  std::vector<std::vector<Eigen::VectorXd>> measured;
  double noise = 0.0;  ///< ScoreBlockNoise of the runs as given (°C)
  /// Per run, the logged ambient's noise at every point (NoiseAtEveryPoint of its samples, °C);
  /// 0 without a log or for an exact one.
  std::vector<double> ambient_noise;
  /// Per run, the standard error of the logged ambient curve's value at the first sample (°C;
  /// LoggedAmbient), the prior of Model::start; 0 without a noisy log.
  std::vector<double> start_sd;
  /// Noise of a fit-block mean of the bias by the gyro file's noise terms (°/h): ARW over the
  /// first run's fit block and the flicker floor, at least 1e-6; what BaselinePrior weighs
  /// against.
  double bias_block_noise = 0.0;
  sim::SolverOptions solver;  ///< CVODE tolerances for this data (SolverForData)

  /// Every run, 0..runs.size()-1.
  std::vector<int> All() const;
  /// The runs scores and held-out RMS are taken on: the held-out runs, or the fit runs when
  /// none is held out.
  std::vector<int> Scored() const;
};

/// The problem of diagnosing `data` against `nominal` with options `o` (valid: IsValid). The
/// problem points into `data`, which must outlive it. InputError as Diagnose: no run to fit on,
/// an unknown fit run, data Prepare refuses, or scored data without one whole score block.
Problem MakeProblem(const sim::Trace& data, const sim::GyroConfig& nominal, const DiagnoseOptions& o);

/// The model the calibration starts from: the nominal knobs, no effect, each run's ambient
/// guessed as the mean of its sensors' first readings (used where it is not logged), starts
/// of 0 and, with per-run gains, gains of 1.
Model NominalModel(const Problem& p);

/// `p` with each fit run's counted fit blocks (and their times and spans) cut to fold `f` of
/// its time: the blocks whose mean time lies in the first or third quarter of the run (f = 0) or
/// in the second or fourth (f = 1): the windows a single run is held out in (SplitInTime). The folds of a run are
/// disjoint and together its blocks; held-out runs are left whole.
Problem InTimeFold(const Problem& p, int f);

/// Means of `v` (a column of run r, or one as long) over run r's counted fit blocks.
Eigen::VectorXd BlockMeans(const Problem& p, const std::vector<double>& v, int r);

/// Score-block means of run r's fit-block residuals `e`: consecutive groups of
/// fit_blocks_per_score, a shorter remainder left out.
std::vector<double> ToScoreBlocks(const Problem& p, const Eigen::Ref<const Eigen::VectorXd>& e, int r);

}  // namespace rlg::diagnosis
