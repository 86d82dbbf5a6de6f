#pragma once
/// End-to-end validation (`rlgtherm validate`): simulate the suite's scenarios, fit a model on
/// the chosen runs (one or more fits, each any model of the family, model/fit_model.h: Eq. (2)
/// as the paper fitted it, or e.g. one auto model for fixed and varying ambients alike), score
/// the sensor pairs (Table 1, Eq. (2)'s), compensate the chosen runs causally (Table 2),
/// read the Allan terms of the compensated bias, and run the checks. Every check compares with
/// the limit the suite wrote (docs/cli.md), and its text states the measured value and that
/// limit:
///   bias      |bias after| <= bias_after_max_dph in the runs selected by bias_after_runs. The
///             floor 3 sigma_B0 is printed beside it as information: sigma_B0, the error of the
///             B0 window mean, is an error no compensator can beat. Only when the suite asks for
///             it (bias_after_floor_sigma = k) is the limit max(bound, k sigma_B0), and then the
///             text says that the limit is the floor and why.
///   stability after <= stability_after_max_dph (at the stated averaging time) and
///             <= stability_100s_after_max_dph (at 100 s); without a limit, after <= before.
///             The text gives the averaging time each was really computed at (whole samples).
///   peak 100s the largest |100 s mean| after compensation <= peak_abs_100s_after_max_dph;
///             without a limit, after <= before (the raw bias's peak, its constant offset
///             included: a weak check, there to report the peak).
/// Which limits a run gets: those of the [[checks.limits]] table one of whose prefixes starts its
/// id (at most one table may; every prefix must start a compensated run), else [checks]'s own,
/// selected by bias_after_runs (bias) and stability_after_runs (stabilities and peak) as before.
///   trend     no significant residual slope against Ti: |slope| <= trend_max_sigma x its SE
///   pair      the best pair by SSE_ave is the expected one (M1 in the paper)
/// Plug-in compensators (validation/plugin.h) named by the suite compensate the same runs as
/// the fitted model and get the same bias, stability and trend checks against the same limits.

#include <array>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "compensation/evaluation.h"
#include "model/allan.h"
#include "model/compensation_model.h"
#include "model/fit_model.h"
#include "model/guo2006.h"
#include "model/pairs.h"
#include "sim/population.h"
#include "sim/scenario.h"
#include "sim/sensor_channels.h"
#include "sim/trace.h"
#include "validation/plugin.h"

namespace rlg::validation {

/// The name the reports give the paper's Eq. (2) compensator; a fit of another model is named
/// by its model ("auto", "poly", "px4", "ardupilot"). A plug-in may take none of these names.
inline constexpr const char* kEq2 = "eq2";
/// The names of the fitted models' compensators, which no other compensator may take.
inline constexpr const char* kFittedCompensatorNames[] = {kEq2, "guo2006", "poly", "px4", "ardupilot", "auto"};

/// An Eq. (2) run whose largest |dT| exceeds this many times the largest |dT| of its fit's runs
/// is warned about: at twice the fitted rise the dT² term is already 4x anything the fit saw.
inline constexpr double kFarBeyondFittedRise = 2.0;

/// One fitted model of a suite: the model, the runs it learns from and the runs it compensates.
struct SuiteFit {
  std::string name;
  model::FitRequest request;  ///< default Eq. (2) for (T1, T2), joint
  std::vector<std::string> fit_runs;
  std::vector<std::string> compensate_runs;
  std::string runs_where, compensate_where;  ///< file:line of the keys, for a run no scenario holds
  std::string where;                         ///< "FILE:LINE" of its name: a fit that fails names it
  /// The name of its compensator in the reports: kEq2 for Eq. (2), else the model's name.
  std::string Compensator() const;
};

/// The limits of the checks of one family of compensated runs: [checks] itself, or one
/// [[checks.limits]] table (scenarios/README.md, "Suite file"). A limit left out is the check's
/// default (bias 0.01 °/h; stabilities and peak: after <= before), never another table's.
struct RunLimits {
  std::vector<std::string> prefixes;  ///< a [[checks.limits]] table's run-id prefixes; empty for [checks]
  std::string where;                  ///< "FILE:LINE: key 'prefixes' in [limits[N]]" (or of [checks])
  double bias_after_max_dph = 0.01;
  double bias_after_floor_sigma = 0.0;  ///< > 0: the bias limit is max(bound, this x sigma_B0); 0: off
  std::optional<double> stability_after_max_dph;       ///< at averaging_s; none: after <= before
  std::optional<double> stability_100s_after_max_dph;  ///< at 100 s; none: after <= before
  std::optional<double> peak_abs_100s_after_max_dph;   ///< largest |100 s mean| after; none: after <= before
  /// Each limit key written -> "FILE:LINE" of it, for the checks' texts (where the limit comes from).
  std::map<std::string, std::string> written;
  /// A prefix of the table starts `run` (always false for [checks] itself).
  bool Selects(const std::string& run) const;
};

struct SuiteSpec {
  std::string path;
  std::vector<std::string> scenarios;  ///< resolved paths
  std::string scenarios_where;         ///< TomlReader::Where("scenarios"): a scenario that cannot be read names it
  std::optional<uint64_t> seed;        ///< overrides every scenario's seed
  std::vector<SuiteFit> fits;          ///< the first one also scores the pairs (Table 1)
  std::vector<std::string> pairs_runs;  ///< empty: the first fit's runs
  double pairs_average_s = 0.0;
  double averaging_s = 1.0;
  bool averaging_explicit = false;  ///< written in the suite: below a run's sample period it is an error
  /// [checks]'s own limits: for the runs no [[checks.limits]] table selects.
  RunLimits limits;
  /// Runs whose id starts with it get the bias check; none: every compensated run. A selector
  /// that is empty or matches no compensated run is refused (InputError naming `*_where`).
  std::optional<std::string> bias_check_prefix;
  std::string bias_check_where;
  std::optional<std::string> stability_check_prefix;  ///< runs the stability and peak limits apply to (none: every compensated run)
  std::string stability_check_where;
  /// [[checks.limits]]: per family of runs, its own limits (refused beside the two selectors above).
  std::vector<RunLimits> run_limits;
  double trend_max_sigma = 3.0;
  std::string trend_where;         ///< "FILE:LINE" of trend_max_sigma; empty: the default
  std::string expected_best_pair;  ///< empty: no check
  std::string best_pair_where;     ///< "FILE:LINE" of best_pair
  /// Plug-in compensators ([[compensators]]): each compensates every run an Eq. (2) fit
  /// compensates, and is evaluated (with that fit's trend channel and B0 window) and checked
  /// like Eq. (2).
  std::vector<PluginCompensator> compensators;
  std::map<std::string, double> paper_sse_ave;                ///< model name -> paper's SSE_ave
  std::map<std::string, std::array<double, 4>> paper_table2;  ///< run -> bias before/after, stability before/after
  /// [population]: the suite runs on every gyro of a part-to-part spread (population_suite.h).
  std::optional<sim::PopulationSpec> population;
  /// [checks] max_failing_fraction, for population suites: a check passes while at most this
  /// fraction of the gyros fails it (0: every gyro must pass).
  double max_failing_fraction = 0.0;
  /// [checks] min_yield, for population suites: the population passes while at least this
  /// fraction of its gyros passes every check (none: the yield is reported, not checked).
  std::optional<double> min_yield;
  /// [checks] baseline_max_sigma: `--baseline` calls a metric regressed beyond this many sigma of
  /// the noise of its two measurements (validation/baseline.h).
  double baseline_max_sigma = 4.0;  ///< default: baseline.h's kBaselineMaxSigma
  std::string min_yield_where;  ///< "FILE:LINE" of min_yield
};

SuiteSpec LoadSuite(const std::string& path);

struct Check {
  std::string name;
  std::string run;  ///< empty for suite-wide checks
  bool passed = false;
  std::string detail;           ///< the measured value, the limit and where the limit comes from
  std::optional<double> value;  ///< what was measured (numeric checks)
  std::optional<double> limit;  ///< what it was compared with: passed is value <= limit
  std::string unit;             ///< of value and limit ("°/h", "°/h/°C"); empty for non-numeric checks
  std::string compensator = kEq2;  ///< whose compensated bias was checked: kEq2 or a plug-in's name
  std::string fit;                 ///< the fit whose runs these are (empty for suite-wide checks)
  /// Where the limit comes from: the key and its "FILE:LINE", or that none was written.
  std::string source;
  /// What the reader must know beside the verdict: the run is compensated beyond the model's
  /// fitted range (SuiteReport::evaluation_warnings). JUnit writes them as properties.
  std::vector<std::string> warnings;
};

struct SuiteReport {
  sim::Trace trace;
  std::vector<model::FittedModel> models;  ///< one per SuiteFit
  std::vector<model::PairScore> pairs;
  std::vector<compensation::RunEvaluation> evaluations;    ///< compensated runs, in suite order; per run the fitted model, then each plug-in
  std::vector<std::string> evaluation_fit;   ///< the fit whose runs these are (its model compensated the fitted rows)
  std::vector<std::string> evaluation_compensator;  ///< the fit's compensator name (SuiteFit::Compensator) or the plug-in's, per evaluation
  std::vector<std::vector<double>> compensated;     ///< the compensated bias (°/h) per evaluation, one value per sample
  /// Per evaluation: where the model was extrapolated on the run. Its Ti0 (Eq. (2)) or samples
  /// (polynomials) outside the fitted range (RunEvaluation::outside_fitted_range, as `compensate`
  /// warns), and, for Eq. (2), a temperature rise dT = Ti - Ti0 beyond kFarBeyondFittedRise
  /// times the largest of the fit's runs: its dT and dT² terms are then a polynomial's
  /// extrapolation, not data (fitted on warm-ups of ~1.5 °C, a 40 °C ramp's dT² term alone can
  /// reach ~100 °/h).
  std::vector<std::vector<std::string>> evaluation_warnings;
  std::vector<Check> checks;
  bool passed() const;
};

SuiteReport RunSuite(const SuiteSpec& spec, const std::function<void(const std::string&)>& progress = nullptr);

/// Adds `run`, compensated by `compensator` (°/h, one value per sample), to `rep` as RunSuite
/// adds the fitted model's and each plug-in's: evaluated with fit `fit`'s model (its trend
/// channel and B0 window; rep.models must hold it) and given the bias, stability, peak and trend
/// checks against the run's limits (its [[checks.limits]] table's, else [checks]'s); `warn`, if
/// given, returns the run's warnings from its evaluation (SuiteReport::evaluation_warnings). For
/// compensators from outside the suite file too (validation/population_suite.h, ExternalCompensator).
void AddCompensatedRun(const SuiteSpec& spec, size_t fit, const sim::Run& run, const std::string& compensator,
                       std::vector<double> compensated, SuiteReport& rep,
                       const std::function<std::vector<std::string>(const compensation::RunEvaluation&)>& warn = nullptr);

/// The suite's scenario files, loaded (InputError naming the file and line of what is wrong).
std::vector<sim::Scenario> LoadSuiteScenarios(const SuiteSpec& spec);

/// Whether RunSuite scores the sensor pairs (Table 1, SuiteReport::pairs) for a report that
/// shows them, or only when a check reads them (`best_pair`): a population keeps each gyro's
/// metrics and checks, not its Table 1, and scoring six pairs is ~8 % of a gyro's CPU.
enum class PairScoring { kAlways, kWhenChecked };

/// The sensor channels the suite's own fits and compensation read, where it can name them: every
/// fit Eq. (2) with its pair, no plug-in compensator and no Table 1 (`best_pair`). Otherwise
/// every channel (`only` empty). A trace simulated with them gives the suite the same checks
/// and metrics as one with every channel (each channel's noise is its own substream).
sim::SensorChannels ChannelsRead(const SuiteSpec& spec);

/// RunSuite on scenarios already loaded: with `gyro`, every scenario's runs are simulated with
/// that gyro instead of the one its file names; with `seed`, it replaces the suite's and the
/// scenarios' seeds (a population's gyro i: sim/population.h); the trace holds the sensor
/// channels `channels` makes (a population's gyro without an outside compensator:
/// ChannelsRead). The `recycled` runs, those of a trace a previous call returned, lend their
/// buffers to the new runs (a population's gyros, one after another on a thread: a run of the
/// same length and channels is neither allocated nor zeroed afresh); the bytes are the same
/// without them.
SuiteReport RunSuite(const SuiteSpec& spec, const std::vector<sim::Scenario>& scenarios, const sim::GyroConfig* gyro,
                     std::optional<uint64_t> seed, const std::function<void(const std::string&)>& progress = nullptr,
                     PairScoring pairs = PairScoring::kAlways, const sim::SensorChannels& channels = {},
                     std::vector<sim::Run> recycled = {});

}  // namespace rlg::validation
