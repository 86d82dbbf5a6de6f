// rlgtherm: the command line. Thin by design: parse, call the libraries, print.
// Exit status (docs/cli.md): 0 ok, 1 internal error or an output that could not be written
// (disk full, I/O error), 2 bad usage or input (an output path the system refuses is usage),
// 3 numerical failure; `validate` adds 4: the checks ran and at least one failed; `plan` adds
// 4: no candidate meets the target, or --verify's realised p95 disagrees with the prediction.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "io/checked_stream.h"
#include "io/process_memory.h"
#include "io/signal_cleanup.h"
#include "sim/errors.h"
#include "tools/rlgtherm/commands.h"

int main(int argc, char** argv) {
  using namespace rlg::cli;
  rlg::io::InstallSignalCleanup();  // no partial output files left behind by Ctrl-C or kill
  rlg::io::KeepFreedMemory();      // reuse freed memory: a population's gyros page-fault less (process_memory.h)
  CLI::App app{"rlgtherm: simulate and compensate the thermal bias of ring laser gyroscopes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rlgtherm " RLG_VERSION);  // CMakeLists.txt project(... VERSION)

  SimulateArgs sim;
  auto* simulate = app.add_subcommand("simulate", "simulate the runs of a scenario file into the tidy CSV run,t_s,T_amb,T1..T4,bias_dph (docs/data-format.md)");
  simulate->add_option("SCENARIO", sim.scenario, "scenario TOML file (scenarios/README.md; a validate suite goes to validate)")->required();
  simulate->add_option("--seed", sim.seed, "random seed (default: the scenario's 'seed', else 1)");
  simulate->add_option("-o,--output", sim.out, "output file: tidy CSV, or numpy's .npz when it ends in .npz ('-' = stdout)");
  simulate->add_option("--gyro", sim.gyro, "gyro I of the scenario's [population] (scenarios/README.md): its drawn "
                                           "parameters and its seed, the same gyro as in a population suite");

  FitArgs fit;
  auto* fit_cmd = app.add_subcommand("fit", "fit a compensation model: the paper's Eq. (2) for a sensor pair, or a "
                                            "polynomial in one channel with optional terms");
  fit_cmd->add_option("DATA", fit.data, "tidy CSV ('-' = stdin)")->required();
  fit_cmd->add_option("--model", fit.model, "guo2006 (Eq. (2); the default where the runs have both channels of --pair), "
                                            "poly (the default otherwise), px4, ardupilot or auto (docs/data-format.md)");
  auto* fit_pair = fit_cmd->add_option("--pair", fit.pair, "guo2006: sensor pair Ti,Tj")->capture_default_str();
  fit_cmd->add_option("--runs", fit.runs, "runs to fit on (default: all)")->delimiter(',');
  fit_cmd->add_option("-o,--output", fit.out, "write the coefficients JSON here ('-' = stdout)");
  auto* fit_method = fit_cmd->add_option("--method", fit.method, "guo2006: joint (all nine A in one least squares) or "
                                                                 "two_stage (the paper's)")->capture_default_str();
  fit_cmd->add_option("--b0-window", fit.b0_window_s, "B0 = mean bias over this many seconds after power-on")->capture_default_str();
  fit_cmd->add_option("--average", fit.average_s, "fit on means over this many seconds (0: the samples as given)")->capture_default_str();
  fit_cmd->add_option("--until", fit.until_s, "fit on each run's samples before this time (s after its first sample); "
                                              "the model's states run from the power-on as in use (a cycle's first part)");
  fit_cmd->add_flag("--json", fit.json, "print the coefficients JSON instead of the summary");
  fit_cmd->add_option("--channel", fit.channel, "poly, px4, ardupilot, auto: the temperature channel (default T1)");
  fit_cmd->add_option("--order", fit.order, "poly: the polynomial's order, 1 to 5 (default 3)");
  fit_cmd->add_option("--terms", fit.terms, "poly: extra terms rate,hysteresis,lag,gradient (gradient:T2 for one "
                                            "channel) or products such as 'T1*(T2-T1)', '(T2-T1)^2', 'rate(T2-T1)'; "
                                            "auto: the library it searches")->delimiter(',');
  fit_cmd->add_option("--beyond-range", fit.beyond_range, "poly: hold (the polynomial held at the fitted range's edge, "
                                                          "the default) or extrapolate");
  fit_cmd->add_option("--offset", fit.offset, "poly, auto: fitted (a constant bias) or power_on (bias minus B0, the "
                                              "polynomial referred to the power-on temperature); default poly: fitted, "
                                              "auto: chosen");
  fit_cmd->add_option("--reference", fit.reference_C, "poly, px4, auto: T_ref in °C (default the middle of the fitted "
                                                      "span; ardupilot: 35)");

  CompareArgs cmp;
  auto* cmp_cmd = app.add_subcommand("compare", "fit every model on training data, score each on held-out data "
                                                "(Table 2 metrics), and select one on the training data alone");
  cmp_cmd->add_option("DATA", cmp.data, "tidy CSV ('-' = stdin)")->required();
  cmp_cmd->add_option("--fit-runs", cmp.fit_runs, "runs to fit on; the others are scored whole (default: each run's "
                                                  "first 70 % in time fitted, the rest scored)")->delimiter(',');
  cmp_cmd->add_option("--cut-at", cmp.cut_s, "cut each run in time here (s after its first sample): fit before, score "
                                              "after, the compensator running on across the cut (default: at 70 % of "
                                              "each run)");
  cmp_cmd->add_option("--channel", cmp.channel, "temperature channel of the polynomial models")->capture_default_str();
  cmp_cmd->add_option("--pair", cmp.pair, "sensor pair of Eq. (2)")->capture_default_str();
  cmp_cmd->add_option("--b0-window", cmp.b0_window_s, "B0 window (s) of the power-on models")->capture_default_str();
  cmp_cmd->add_flag("--json", cmp.json, "machine-readable output (keys: docs/data-format.md)");
  cmp_cmd->add_option("--plot", cmp.plot, "directory for figures: heldout_<model>.png, each model's held-out "
                                          "compensated bias against temperature");

  PairsArgs pairs;
  auto* pairs_cmd = app.add_subcommand("pairs", "Table 1: SSE per run and SSE_ave for M1..M6");
  pairs_cmd->add_option("DATA", pairs.data, "tidy CSV ('-' = stdin)")->required();
  pairs_cmd->add_option("--runs", pairs.runs, "runs to use (default: all)")->delimiter(',');
  pairs_cmd->add_flag("--all", pairs.all, "every ordered pair of the temperature channels, not only M1..M6");
  pairs_cmd->add_option("--average", pairs.average_s, "work on means over this many seconds (the paper: 60)")->capture_default_str();
  pairs_cmd->add_option("--b0-window", pairs.b0_window_s, "B0 window (s)")->capture_default_str();
  pairs_cmd->add_flag("--json", pairs.json, "machine-readable output (keys: docs/data-format.md)");

  CompensateArgs comp;
  auto* comp_cmd = app.add_subcommand("compensate", "Table 2: bias and stability before/after causal compensation");
  comp_cmd->add_option("DATA", comp.data, "tidy CSV ('-' = stdin)")->required();
  comp_cmd->add_option("--coeffs", comp.coeffs, "coefficients JSON from 'fit'")->required();
  comp_cmd->add_option("-o,--output", comp.out, "write the data with a bias_comp_dph column ('-' = stdout)");
  auto* averaging = comp_cmd->add_option("--averaging", comp.averaging_s,
                                         "averaging time (s) of the stability columns: whole samples, at least one "
                                         "(the default 1 s is raised to the sample period of coarser data, saying so)")
                        ->capture_default_str();
  comp_cmd->add_option("--column", comp.column, "bias column to compensate and evaluate (°/h)")->capture_default_str();
  comp_cmd->add_option("--from", comp.from_s, "Table 2 of each run's samples from this time on (s after its first "
                                              "sample), compensated from its power-on (the part a fit --until left out)");
  comp_cmd->add_flag("--stream", comp.stream,
                     "sample by sample: read rows and write each compensated row to stdout at once");
  comp_cmd->add_flag("--json", comp.json, "machine-readable output (keys: docs/data-format.md)");
  comp_cmd->add_option("--plot", comp.plot, "directory for figures: bias_<run>.png (before/after, temperatures) and "
                                            "allan_<run>.png (compensated bias); not with --stream");

  EvaluateArgs eval;
  auto* eval_cmd = app.add_subcommand("evaluate", "Table 2 for a compensated column of your own: bias and stability before/after, trend, Allan read-offs");
  eval_cmd->add_option("DATA", eval.data, "tidy CSV ('-' = stdin) holding the raw and the compensated bias")->required();
  eval_cmd->add_option("--compensated", eval.compensated, "the compensated bias column (°/h)")->required();
  eval_cmd->add_option("--column", eval.column, "the raw bias column (°/h)")->capture_default_str();
  auto* eval_averaging = eval_cmd->add_option("--averaging", eval.averaging_s,
                                              "averaging time (s) of the stability columns (as for compensate)")
                             ->capture_default_str();
  eval_cmd->add_option("--trend-channel", eval.trend_channel, "temperature the residual trend is regressed on")
      ->capture_default_str();
  eval_cmd->add_option("--b0-window", eval.b0_window_s, "window (s) whose mean's error is reported as b0_error_dph")
      ->capture_default_str();
  eval_cmd->add_flag("--json", eval.json, "machine-readable output, the keys of compensate --json (docs/data-format.md)");
  eval_cmd->add_option("--plot", eval.plot, "directory for figures: bias_<run>.png and allan_<run>.png (as compensate)");

  AllanArgs allan;
  auto* allan_cmd = app.add_subcommand("allan", "Allan deviation with ARW, bias instability and RRW read-offs");
  allan_cmd->add_option("DATA", allan.data, "tidy CSV ('-' = stdin)")->required();
  allan_cmd->add_option("--run", allan.run, "one run (default: every run)");
  allan_cmd->add_option("--column", allan.column, "rate column to analyse (°/h), e.g. your own compensated bias")
      ->capture_default_str();
  allan_cmd->add_flag("--json", allan.json, "machine-readable output (keys: docs/data-format.md)");
  allan_cmd->add_option("--plot", allan.plot, "directory for figures: allan_<run>.png with the fitted noise lines");

  ValidateArgs validate;
  auto* validate_cmd = app.add_subcommand("validate", "end to end: simulate -> fit -> compensate -> checks");
  validate_cmd->add_option("SUITE", validate.suite, "suite TOML file")->required();
  validate_cmd->add_flag("--json", validate.json, "machine-readable output");
  validate_cmd->add_option("--seed", validate.seed, "random seed for every scenario (default: the suite's 'seed', else each scenario's)");
  validate_cmd->add_option("--junit", validate.junit, "also write the checks as JUnit XML to this file (docs/data-format.md)");
  validate_cmd->add_option("--plot", validate.plot, "directory for figures: table1.png, and bias_<run>.png and "
                                                    "allan_<run>.png of each compensated run");
  validate_cmd->add_option("--threads", validate.threads, "population suites: gyros in parallel on N threads "
                                                          "(default 0: one per core; the output does not depend on it)")
      ->check(CLI::Range(0, 1024));
  validate_cmd->add_option("--gyros", validate.gyros, "population suites: write one CSV row per gyro (its id, seed, "
                                                      "drawn parameters and metrics) to this file");
  validate_cmd->add_option("--gyro", validate.gyro, "population suites: run gyro I alone and print its one-gyro "
                                                    "report (the same numbers as its row in --gyros)");
  validate_cmd->add_option("--baseline", validate.baseline, "a previous --json of the suite: compare each metric with it "
                                                            "against their noise; exit 4 when one regressed (docs/cli.md)");

  PlanArgs plan;
  auto* plan_cmd = app.add_subcommand("plan", "predict what calibration protocols leave in service, before the chamber is booked (docs/plan.md)");
  plan_cmd->add_option("PLAN", plan.plan, "plan TOML file (docs/plan.md)")->required();
  plan_cmd->add_flag("--json", plan.json, "machine-readable output");
  plan_cmd->add_option("--plot", plan.plot, "directory for pareto.png: chamber hours against p95 |bias after|");
  plan_cmd->add_option("--threads", plan.threads, "gyros in parallel on N threads (default: one per core); the output "
                       "does not depend on N")->check(CLI::NonNegativeNumber);
  plan_cmd->add_option("--verify", plan.verify, "draw N fresh gyros through the recommended candidate and print the "
                       "realised p95 beside the predicted one");
  plan_cmd->add_option("--gyros", plan.gyros, "FROM:TO: simulate gyros FROM .. TO-1 only and print that shard's "
                       "JSON, for --merge (a plan on several machines, docs/plan.md)");
  plan_cmd->add_option("--merge", plan.merge, "conclude from the shards of --gyros instead of simulating: the same "
                       "output as the plan run in one piece");

  DiagnoseArgs diag;
  auto* diag_cmd = app.add_subcommand("diagnose", "calibrate the gyro to data, name what it misses, extend it (or, "
                                                  "without --gyro, what the best polynomial in temperature misses)");
  diag_cmd->add_option("DATA", diag.data, "tidy CSV ('-' = stdin); bias_dph optional (thermal-only data)")->required();
  diag_cmd->add_option("--gyro", diag.gyro, "nominal gyro TOML; without it, the bias is searched alone against the "
                                            "measured temperatures (a polynomial baseline, no thermal network)");
  diag_cmd->add_option("--max-steps", diag.max_steps, "extensions to accept at most")->capture_default_str();
  diag_cmd->add_option("--fit-runs", diag.fit_runs, "runs to fit on; the others are held out (default: all, cross-validated)")
      ->delimiter(',');
  diag_cmd->add_flag("--per-run-gains", diag.per_run_gains,
                     "each run has its own gain for every data-driven source (runs from different boards)");
  diag_cmd->add_flag("--json", diag.json, "the diagnosis report as JSON on stdout (keys: docs/data-format.md)");
  diag_cmd->add_option("--report", diag.report, "directory for diagnosis.json, residuals.csv, extended-gyro.toml (with --gyro) and "
                                              "fit_<channel>.png figures");

  ImportArgs imp;
  auto* import_cmd = app.add_subcommand("import", "convert measured logs to the tidy CSV");
  import_cmd->add_option("FORMAT", imp.format,
                          "log format: tclab (TCLab logs, one run each) or columns (any delimited log with a header "
                          "row: comma, tab or semicolon)")->required();
  import_cmd->add_option("FILES", imp.files, "log files (columns: one)")->required();
  import_cmd->add_option("-o,--output", imp.out, "output CSV ('-' = stdout)");
  import_cmd->add_option("--time", imp.time, "columns: the time column and its unit, COL:s, COL:ms, COL:us or COL:ns; t_s counts from the first row");
  import_cmd->add_option("--temp", imp.temps, "columns: temperature columns in °C, COL[,COL..], written as T1, T2, ..")
      ->delimiter(',');
  import_cmd->add_option("--rate", imp.rate, "columns: the rate column and its unit, COL:dph, COL:dps or COL:radps, written as bias_dph in °/h");
  import_cmd->add_option("--run", imp.run, "columns: the run id (default: the file name without extension)");
  import_cmd->add_option("--split-at", imp.split_at_s, "columns: cut the log into runs ID-1, ID-2, .. at these times (s from the first row)")
      ->delimiter(',');

  ExportArgs exp;
  auto* export_cmd = app.add_subcommand("export", "write a coefficient file's compensator as C99 code for the gyro's "
                                                  "processor (docs/firmware.md)");
  export_cmd->add_option("COEFFS", exp.coeffs, "coefficients JSON from 'fit' (any model)")->required();
  export_cmd->add_option("--c", exp.c_dir, "directory for <prefix>.h and <prefix>.c (created if missing; files of "
                                           "other names in it are left alone)")->required();
  auto* as_float = export_cmd->add_flag("--float", exp.use_float, "float arithmetic (for an FPU without double)");
  auto* as_double = export_cmd->add_flag("--double", "double arithmetic (the default)");
  as_float->excludes(as_double);
  export_cmd->add_option("--prefix", exp.prefix, "the files' stem and the names' prefix: <prefix>_state, "
                                                 "<prefix>_init, <prefix>_update")->capture_default_str();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    // Bad usage, with the prefix of every other refusal (docs/cli.md, "Exit statuses").
    std::vector<std::string> verbs;
    for (const auto* v : app.get_subcommands([](const CLI::App*) { return true; })) verbs.push_back(v->get_name());
    std::string message = e.what(), verb;
    for (const auto& v : verbs)
      if (argc >= 2 && v == argv[1]) verb = v;
    if (verb.empty() && (argc < 2 || std::string_view(argv[1]).rfind('-', 0) != 0)) {
      message = argc < 2 ? "expected a verb" : fmt::format("unknown verb '{}'", argv[1]);
      message += fmt::format("; the verbs are {}", fmt::join(verbs, ", "));
    }
    fmt::print(stderr, "rlgtherm: error: {} (rlgtherm{} --help)\n", message, verb.empty() ? "" : " " + verb);
    return 2;
  }
  try {
    int status = 1;
    if (simulate->parsed()) status = RunSimulate(sim);
    if (fit_cmd->parsed()) {
      fit.pair_given = fit_pair->count() > 0;
      fit.method_given = fit_method->count() > 0;
      status = RunFit(fit);
    }
    if (cmp_cmd->parsed()) status = RunCompare(cmp);
    if (pairs_cmd->parsed()) status = RunPairs(pairs);
    if (comp_cmd->parsed()) {
      comp.averaging_explicit = averaging->count() > 0;
      status = RunCompensate(comp);
    }
    if (eval_cmd->parsed()) {
      eval.averaging_explicit = eval_averaging->count() > 0;
      status = RunEvaluate(eval);
    }
    if (allan_cmd->parsed()) status = RunAllan(allan);
    if (validate_cmd->parsed()) status = RunValidate(validate);
    if (plan_cmd->parsed()) status = RunPlan(plan);
    if (diag_cmd->parsed()) status = RunDiagnose(diag);
    if (import_cmd->parsed()) status = RunImport(imp);
    if (export_cmd->parsed()) status = RunExport(exp);
    rlg::io::CheckStdout();  // a summary or data lost on a full disk or closed pipe is a failure
    return status;
  } catch (const rlg::InputError& e) {
    fmt::print(stderr, "rlgtherm: error: {}\n", e.what());
    return 2;
  } catch (const rlg::NumericalError& e) {
    fmt::print(stderr, "rlgtherm: numerical failure: {}\n", e.what());
    return 3;
  } catch (const rlg::OutputError& e) {
    fmt::print(stderr, "rlgtherm: error: {}\n", e.what());
    return 1;
  } catch (const std::system_error& e) {
    // fmt::print throws this when stdout does not take the text (disk full, closed pipe).
    if (std::ferror(stdout)) {
      fmt::print(stderr, "rlgtherm: error: standard output: writing failed: {}\n", e.code().message());
    } else {
      fmt::print(stderr, "rlgtherm: internal error: {}\n", e.what());
    }
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "rlgtherm: internal error: {}\n", e.what());
    return 1;
  }
}
