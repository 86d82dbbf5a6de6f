#pragma once
// The verbs of docs/cli.md. Each verb's file registers its subcommand (Register<Verb>: the
// options and their --help text) and runs it (Run<Verb>, the process exit status); kVerbs lists
// them in the order of `rlgtherm --help`.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "model/b0_window.h"
#include "model/fit_model.h"

namespace CLI {
class App;
}

namespace rlg::cli {

/// A verb on the command line: its subcommand, and its run once the command line has parsed with
/// that subcommand given (the process exit status).
struct Verb {
  CLI::App* command = nullptr;
  std::function<int()> run;
};

struct SimulateArgs {
  std::string scenario;
  std::optional<uint64_t> seed;
  std::string out = "-";
  std::optional<uint64_t> gyro;  ///< gyro I of the scenario's [population]
};
int RunSimulate(const SimulateArgs& a);
Verb RegisterSimulate(CLI::App& app);

struct FitArgs {
  std::string data;
  /// The model and its options (model/fit_model.h) but the pair and the method, which are read
  /// as text here: --model empty is guo2006 where the runs have the pair's two channels (or
  /// --pair is given), else poly.
  model::FitRequest request;
  std::string pair = "T1,T2";
  bool pair_given = false;
  std::vector<std::string> runs;
  std::string out;
  std::string method = "joint";
  bool method_given = false;
  double average_s = 0.0;
  std::optional<double> until_s;  ///< --until: fit on each run's samples before this time (s after its first)
  bool json = false;
};
int RunFit(const FitArgs& a);
Verb RegisterFit(CLI::App& app);

/// Every model fitted on the same training data and scored on the same held-out data
/// (compensation/model_comparison.h).
struct CompareArgs {
  std::string data;
  std::vector<std::string> fit_runs;
  std::string channel = "T1";
  std::string pair = "T1,T2";
  double b0_window_s = model::kB0Window_s;
  double train_fraction = 0.7;
  std::optional<double> cut_s;  ///< --cut-at: each run fitted before this time (s after its first sample), scored after
  bool json = false;
  std::string plot;  ///< --plot DIR: heldout_<model>.png per model
};
int RunCompare(const CompareArgs& a);
Verb RegisterCompare(CLI::App& app);

struct PairsArgs {
  std::string data;
  std::vector<std::string> runs;
  bool all = false;
  bool json = false;
  double average_s = 0.0;
  double b0_window_s = model::kB0Window_s;
};
int RunPairs(const PairsArgs& a);
Verb RegisterPairs(CLI::App& app);

struct CompensateArgs {
  std::string data;
  std::string coeffs;
  std::string out;
  bool json = false;
  bool stream = false;
  double averaging_s = 1.0;
  bool averaging_explicit = false;  ///< --averaging given: below the sample period is an error
  std::string column = "bias_dph";  ///< the bias column to compensate
  std::string plot;                 ///< --plot DIR: bias_<run>.png and allan_<run>.png
  std::optional<double> from_s;     ///< --from: Table 2 of each run's samples from this time on
};
int RunCompensate(const CompensateArgs& a);
Verb RegisterCompensate(CLI::App& app);

/// Table 2 for a compensated column the data already holds (a user's own algorithm).
struct EvaluateArgs {
  std::string data;
  std::string compensated;          ///< the compensated bias column (°/h)
  std::string column = "bias_dph";  ///< the raw bias column it is compared with
  std::string trend_channel = "T1";
  double b0_window_s = model::kB0Window_s;
  double averaging_s = 1.0;
  bool averaging_explicit = false;
  bool json = false;
  std::string plot;  ///< --plot DIR: bias_<run>.png and allan_<run>.png
};
int RunEvaluate(const EvaluateArgs& a);
Verb RegisterEvaluate(CLI::App& app);

struct AllanArgs {
  std::string data;
  std::string run;
  std::string column = "bias_dph";
  bool json = false;
  std::string plot;  ///< --plot DIR: allan_<run>.png
};
int RunAllan(const AllanArgs& a);
Verb RegisterAllan(CLI::App& app);

struct ValidateArgs {
  std::string suite;
  bool json = false;
  std::optional<uint64_t> seed;  ///< overrides the suite's seed and its scenarios'
  std::string junit;             ///< write the checks as JUnit XML here
  std::string plot;              ///< --plot DIR: table1.png, bias_<run>.png, allan_<run>.png
  // Population suites ([population], docs/results.md, Populations).
  int threads = 0;               ///< 0: one per core
  std::string gyros;             ///< --gyros FILE: one CSV row per gyro (population_report.h)
  std::optional<uint64_t> gyro;  ///< --gyro I: gyro I alone, with the one-gyro report
  std::string baseline;          ///< --baseline OLD.json: a previous --json, each metric compared (baseline.h)
};
int RunValidate(const ValidateArgs& a);
Verb RegisterValidate(CLI::App& app);

/// A calibration-protocol plan (validation/plan.h, docs/plan.md).
struct PlanArgs {
  std::string plan;
  bool json = false;
  std::string plot;     ///< --plot DIR: pareto.png
  int threads = 0;      ///< 0: one per core
  uint64_t verify = 0;  ///< --verify N: N fresh gyros through the recommended candidate
  std::string gyros;    ///< --gyros FROM:TO: simulate that shard and print its JSON
  std::vector<std::string> merge;  ///< --merge SHARD.json..: conclude from shards
};
int RunPlan(const PlanArgs& a);
Verb RegisterPlan(CLI::App& app);

struct DiagnoseArgs {
  std::string data;
  std::string gyro;
  int max_steps = 3;
  int lookahead = 2;
  std::vector<std::string> fit_runs;
  bool per_run_gains = false;
  bool power = false;
  bool json = false;
  std::string report;
};
int RunDiagnose(const DiagnoseArgs& a);
Verb RegisterDiagnose(CLI::App& app);

struct ImportArgs {
  std::string format;
  std::vector<std::string> files;
  std::string out = "-";
  // import columns: COL[:unit] of the time and the rate, the temperature columns, the run id
  // and the times to split the log at.
  std::string time, rate, run;
  std::vector<std::string> temps;
  std::vector<double> split_at_s;
};
int RunImport(const ImportArgs& a);
Verb RegisterImport(CLI::App& app);

/// A coefficient file as C code for the gyro's processor (compensation/c_export.h).
struct ExportArgs {
  std::string coeffs;
  std::string c_dir;  ///< --c DIR
  bool use_float = false;
  std::string prefix = "rlg_comp";
};
int RunExport(const ExportArgs& a);
Verb RegisterExport(CLI::App& app);

/// The verbs in the order of `rlgtherm --help` and of its error message's list.
inline constexpr Verb (*kVerbs[])(CLI::App&) = {
    RegisterSimulate, RegisterFit,      RegisterCompare,  RegisterPairs,    RegisterCompensate, RegisterEvaluate,
    RegisterAllan,    RegisterValidate, RegisterPlan,     RegisterDiagnose, RegisterImport,     RegisterExport};

}  // namespace rlg::cli
