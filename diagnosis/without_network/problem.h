#pragma once
/// Stage 1 of a diagnosis without a thermal network (docs/diagnosis.md, "Without a thermal
/// network"): the problem, built once from data with measured temperatures and a bias, never
/// changed. Everything later is a function of it and the columns it is given.
///
///  - the channels: the temperature channels every run has (model/pairs.h TemperatureChannels:
///    T1, T2, .., T_name; not T_amb), in the first run's order, and the bias-temperature channel
///    the baseline polynomial is in: T1, else the first of them;
///  - per run, its fit blocks in whole samples (data/prepare.h: BlockLayout, Blocks; 10 s by
///    default) and per block the means of each channel (°C), their rates (°C/s: central
///    differences of the block means, one-sided at the ends, RatePerMinute / 60) and the means
///    of the bias (°/h). History-dependent terms (hysteresis, a lag) are computed over whole
///    runs from their first sample, whichever blocks count;
///  - the held-out split, as the diagnosis against a network makes it (network/problem.h): runs named
///    in fit_runs are fitted and the others scored; without them every run is fitted and scored
///    leave-one-run-out; a single run is cut in time into single_run_pieces contiguous pieces
///    (SplitInTime), fitted on the even ones and scored on the odd ones. Samples are never
///    interleaved between fit and score.
///
/// The bias regression of stage 5 (statistics/bias_fit.h) then runs on units: a run, or the fitted or the
/// held-out pieces of one, each with its own offset (BiasResidual centres it).

#include <Eigen/Core>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/statistics/bias_fit.h"
#include "diagnosis/options.h"
#include "diagnosis/data/prepare.h"
#include "diagnosis/statistics/score.h"
#include "sim/trace.h"

namespace rlg::diagnosis {

/// A unit of the bias regression: a run, or the fitted or held-out pieces of one.
struct MeasuredUnit {
  PreparedRun prepared;        ///< the run (or pieces), its label, windows and block layout
  int run = 0;                 ///< index into MeasuredProblem::runs
  std::vector<size_t> blocks;  ///< the run's blocks that count for this unit, in time order
};

/// A column of the regression (a regressor, or the bias itself): per run, one value per fit
/// block of the whole run.
using RunColumns = std::vector<Eigen::VectorXd>;

struct MeasuredProblem {
  DiagnoseOptions options;
  std::vector<std::string> channels;  ///< temperature channels every run has
  std::string channel;                ///< the bias-temperature channel (the polynomial's)
  int channel_index = 0;              ///< its index in `channels`
  std::vector<const sim::Run*> runs;  ///< the data's runs, which must outlive the problem
  /// Per run: its fit blocks (samples [first, second)), their mean sample times (s), the block
  /// means of each channel (channels x blocks, °C) and their rates (°C/s), and of the bias (°/h).
  std::vector<std::vector<std::pair<size_t, size_t>>> blocks;
  std::vector<std::vector<double>> block_times;
  std::vector<Eigen::MatrixXd> T, Tdot;
  RunColumns bias;
  std::vector<MeasuredUnit> units;
  std::vector<int> fit, held;  ///< indices into units
  std::string split_note;      ///< how a single run was split in time, if it was

  /// The units scores and held-out RMS are taken on: the held-out ones, or the fitted ones
  /// when none is held out (leave-one-run-out).
  std::vector<int> Scored() const;
};

/// The problem of `data` with options `o` (valid: IsValid). InputError naming the file and run
/// for a run without bias_dph or without a temperature channel every run has, a run of fewer
/// than 20 samples, an unknown fit run, per-run source gains (an option of a thermal network),
/// or scored data without one whole score block.
MeasuredProblem MakeMeasuredProblem(const sim::Trace& data, const DiagnoseOptions& o);

/// Per run, the block means of the series `samples(run)` gives (one value per sample).
RunColumns BlockMeansOf(const MeasuredProblem& p, const std::function<std::vector<double>(int run)>& samples);

/// The regression of `y` (per run, per block) on `columns` over the units (statistics/bias_fit.h): per
/// unit its counted blocks; no prior (every coefficient free).
BiasDesign MeasuredDesign(const MeasuredProblem& p, const std::vector<const RunColumns*>& columns, const RunColumns& y);

/// Score-block means of unit u's block residuals `e`: consecutive groups of its
/// fit_blocks_per_score, a shorter remainder left out (ToScoreBlocks of network/problem.h).
std::vector<double> UnitScoreBlocks(const MeasuredProblem& p, const Eigen::VectorXd& e, int u);

/// A regression's fit: in sample (fit-block residuals of the fitted units, the information
/// criterion's input) and held out (score-block means of the scored units' HeldOutBias
/// residuals, the held-out RMS ratio's), and the held-out residuals themselves.
struct MeasuredFit {
  ResidualFit in_sample, held_out;
  std::vector<Eigen::VectorXd> held_residuals;  ///< per unit; empty for units not scored
};
MeasuredFit FitMeasured(const MeasuredProblem& p, const BiasDesign& d);

/// The in-sample sum of squares alone (what a profile search minimises).
double InSampleSsr(const MeasuredProblem& p, const BiasDesign& d);

}  // namespace rlg::diagnosis
