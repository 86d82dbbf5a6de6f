// Verb validate: simulate -> fit -> compensate -> checks, with the paper's numbers alongside.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <unistd.h>

#include "compensation/evaluation_report.h"
#include "io/atomic_output.h"
#include "model/coefficients_json.h"
#include "tools/rlgtherm/commands.h"
#include "tools/rlgtherm/common.h"
#include "tools/rlgtherm/plot_kit.h"
#include "tools/rlgtherm/verb_figures.h"
#include "validation/baseline.h"
#include "validation/population_report.h"
#include "validation/population_suite.h"
#include "validation/suite.h"
#include "validation/suite_junit.h"

namespace rlg::cli {
namespace {

/// --plot of validate: Table 1, and per compensated run (and compensator) the bias before and
/// after and the Allan curve of the compensated bias.
void DrawSuiteFigures(FigureDirectory& figures, const validation::SuiteSpec& spec, const validation::SuiteReport& rep) {
  figures.WriteTable1(rep.pairs, spec.paper_sse_ave, spec.pairs_average_s);
  for (size_t i = 0; i < rep.evaluations.size(); ++i) {
    const auto& e = rep.evaluations[i];
    const sim::Run& run = rep.trace.FindRun(e.run);
    const std::string& by = rep.evaluation_compensator[i];
    const bool eq2 = by == validation::kEq2;
    const std::string label = eq2 ? fmt::format("Eq. (2), fit '{}'", rep.evaluation_fit[i]) : by;  // a model's name or a plug-in's
    const std::string suffix = eq2 ? "" : "_" + plot::FileNamePart(by);
    figures.WriteBias(run, run.Column("bias_dph"), "bias_dph", rep.compensated[i], label, suffix);
    figures.WriteAllan(e.run, fmt::format("the compensated bias ({})", label), e.allan, e.noise, suffix);
  }
}

/// validate's progress on stderr, with the time left estimated from the mean time per step so
/// far. On a terminal one line rewritten in place at each step; elsewhere (a CI log) one line
/// each time another 10 % of the steps is done, so that a long run shows it is alive without
/// flooding the log. Stdout is untouched: the report stays the same bytes.
class Progress {
 public:
  Progress(size_t total, std::string unit)
      : total_(std::max<size_t>(total, 1)), unit_(std::move(unit)), tty_(::isatty(STDERR_FILENO) != 0),
        start_(std::chrono::steady_clock::now()) {}
  /// One more step done; `what` names it.
  void Step(const std::string& what) {
    done_ = std::min(done_ + 1, total_);
    const size_t percent = 100 * done_ / total_;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double left = elapsed / static_cast<double>(done_) * static_cast<double>(total_ - done_);
    if (tty_) {
      fmt::print(stderr, "\r{} ({} of {} {}, {} %, about {} left)\x1b[K", what, done_, total_, unit_, percent,
                 Duration(left));
    } else if (percent >= next_percent_) {
      fmt::print(stderr, "rlgtherm: validate: {} % ({} of {} {}: {}), {} elapsed, about {} left\n", percent, done_, total_,
                 unit_, what, Duration(elapsed), Duration(left));
      next_percent_ = percent - percent % 10 + 10;
    }
  }
  /// Clears the terminal's progress line (nothing to do in a log).
  void Done() const {
    if (tty_) fmt::print(stderr, "\r\x1b[K");
  }

 private:
  static std::string Duration(double s) {
    if (s < 10.0) return fmt::format("{:.1f} s", s);
    if (s < 60.0) return fmt::format("{:.0f} s", s);
    if (s < 3600.0) return fmt::format("{:.0f} min {:02.0f} s", std::floor(s / 60.0), std::fmod(s, 60.0));
    return fmt::format("{:.0f} h {:02.0f} min", std::floor(s / 3600.0), std::floor(std::fmod(s, 3600.0) / 60.0));
  }
  size_t total_, done_ = 0, next_percent_ = 10;
  std::string unit_;
  bool tty_;
  std::chrono::steady_clock::time_point start_;
};

void AppendChecks(std::vector<validation::Check>& to, std::vector<validation::Check> more) {
  to.insert(to.end(), std::make_move_iterator(more.begin()), std::make_move_iterator(more.end()));
}

/// A population suite: every gyro through the suite on a thread pool, the per-gyro rows streamed
/// to --gyros, and the distributions printed (validation/population_report.h).
int RunPopulationValidate(const ValidateArgs& a, validation::SuiteSpec spec, const std::optional<nlohmann::json>& baseline) {
  if (!a.plot.empty()) throw InputError("--plot draws one gyro's runs: with a population suite, add --gyro I");
  const uint64_t n = spec.population->count;
  Progress progress(n, "gyros");
  const validation::PopulationSuite suite(std::move(spec));  // runs gyro 0 once to fix the layout
  validation::PopulationSummary summary(suite);
  nlohmann::json report;
  std::optional<validation::BaselineReport> regression;
  auto run = [&](std::ostream* rows) {
    if (rows) *rows << validation::PopulationCsvHeader(suite);
    validation::RunPopulation(suite, 0, n, a.threads, [&](const validation::GyroOutcome& g) {
      summary.Add(g);
      if (rows) *rows << validation::PopulationCsvRow(g);
      progress.Step(fmt::format("gyro {}", g.index));
    });
    report = validation::PopulationJson(suite, summary);
    if (baseline) {
      regression = validation::CompareWithBaseline(report, *baseline, a.baseline, suite.spec().baseline_max_sigma);
    }
    // The JUnit file inside the CSV's writer: when it cannot be written, the CSV is not kept
    // either (no partial output, docs/cli.md).
    if (!a.junit.empty()) {
      validation::SuiteReport checks_only;
      checks_only.checks = validation::PopulationChecks(suite, summary);
      if (regression) AppendChecks(checks_only.checks, validation::BaselineChecks(*regression));
      WriteText(a.junit, validation::SuiteJunitXml(checks_only, std::filesystem::path(a.suite).stem().string()));
    }
  };
  if (a.gyros.empty()) {
    run(nullptr);
  } else {
    io::WriteFileAtomically(a.gyros, [&](std::ostream& out) { run(&out); });
  }
  progress.Done();
  const bool passed = summary.passed() && (!regression || regression->passed());
  if (a.json) {
    if (regression) report["baseline"] = validation::BaselineJson(*regression);
    report["passed"] = passed;
    fmt::print("{}\n", report.dump(2));
  } else {
    fmt::print("{}", validation::PopulationText(suite, summary));
    if (regression) fmt::print("{}", validation::BaselineText(*regression));
  }
  return passed ? 0 : 4;
}

int RunValidateOrThrow(const ValidateArgs& a);

}  // namespace

int RunValidate(const ValidateArgs& a) {
  // A validate that cannot run still leaves its JUnit file, with one errored testcase saying why
  // (the pipeline shows the configuration error, not a missing or stale report); the error is
  // then reported and exits as any other (2, 3). When the file itself cannot be written, the
  // first error is the one reported.
  auto junit_error = [&](const char* type, const std::exception& e) {
    if (a.junit.empty()) return;
    try {
      WriteText(a.junit, validation::ErrorJunitXml(std::filesystem::path(a.suite).stem().string(), type, e.what()));
    } catch (const std::exception&) {
    }
  };
  try {
    return RunValidateOrThrow(a);
  } catch (const InputError& e) {
    junit_error("InputError", e);
    throw;
  } catch (const NumericalError& e) {
    junit_error("NumericalError", e);
    throw;
  }
}

namespace {

/// --gyro I: gyro I of the population suite alone, the same draw and seed as in the
/// population's run; `gyro_json` and `gyro_text` say which gyro it is and its drawn parameters.
validation::SuiteReport ReportOneGyro(const ValidateArgs& a, const validation::SuiteSpec& spec, nlohmann::json& gyro_json,
                                      std::string& gyro_text) {
  const validation::PopulationSuite suite(spec);
  sim::Population::Gyro drawn;
  validation::SuiteReport rep = suite.Report(*a.gyro, &drawn);
  gyro_json = {{"index", drawn.index}, {"seed", drawn.seed}, {"suite_seed", suite.seed()},
               {"gyros", suite.population().count()}, {"parameters", nlohmann::json::array()}};
  gyro_text = fmt::format("Gyro {} of the {} gyros of {} (seed {}, SplitMix64 of the suite seed {} and {}); drawn parameters "
                          "(nominal in brackets):\n",
                          drawn.index, suite.population().count(), a.suite, drawn.seed, suite.seed(), drawn.index);
  for (size_t k = 0; k < suite.parameters().size(); ++k) {
    const double nominal = suite.population().nominal_values()[k];
    gyro_json["parameters"].push_back(
        {{"name", suite.parameters()[k]}, {"value", drawn.values[k]}, {"nominal", nominal}});
    gyro_text += fmt::format("  {:<48} {:.6g} ({:.6g})\n", suite.parameters()[k], drawn.values[k], nominal);
  }
  gyro_text += "\n";
  return rep;
}

/// The report as --json prints it (without "gyro", "baseline" and "passed"): the coefficients,
/// Table 1, Table 2 and the checks.
nlohmann::json SuiteReportJson(const validation::SuiteSpec& spec, const validation::SuiteReport& rep) {
  nlohmann::json j;
  for (size_t f = 0; f < spec.fits.size(); ++f) j["coefficients"][spec.fits[f].name] = model::ModelToJson(rep.models[f]);
  for (const auto& s : rep.pairs) j["table1"][s.combination.name] = s.sse_ave;
  j["best_pair"] = model::BestPair(rep.pairs).combination.name;
  j["table2"] = nlohmann::json::array();
  for (size_t i = 0; i < rep.evaluations.size(); ++i) {
    nlohmann::json row = compensation::EvaluationJson(rep.evaluations[i]);
    row["fit"] = rep.evaluation_fit[i];
    row["compensator"] = rep.evaluation_compensator[i];
    row["warnings"] = rep.evaluation_warnings[i];
    j["table2"].push_back(row);
  }
  j["checks"] = nlohmann::json::array();
  for (const auto& c : rep.checks) {
    nlohmann::json check = {{"check", c.name},     {"run", c.run},       {"compensator", c.compensator},
                            {"passed", c.passed}, {"detail", c.detail}};
    if (c.value) check["value"] = *c.value;
    if (c.limit) check["limit"] = *c.limit;
    if (!c.unit.empty()) check["unit"] = c.unit;
    j["checks"].push_back(check);
  }
  return j;
}

/// Each fit's model in one line.
void PrintFits(const validation::SuiteSpec& spec, const validation::SuiteReport& rep) {
  for (size_t f = 0; f < spec.fits.size(); ++f) {
    const auto& m = rep.models[f];
    if (const auto* c = std::get_if<model::Guo2006Coefficients>(&m)) {
      fmt::print("Fit '{}': Eq. (2), pair ({}, {}), {} on {} runs ({}); scaled condition number {:.3g}, residual RMS "
                 "{:.4f} °/h\n",
                 spec.fits[f].name, c->pair[0], c->pair[1], model::Guo2006MethodName(c->method), c->runs.size(), fmt::join(c->runs, ", "),
                 c->condition_number, c->residual_rms_dph);
    } else {
      const auto& p = std::get<model::PolyModel>(m);
      fmt::print("Fit '{}': {} ({}) on {} runs ({}); scaled condition number {:.3g}, residual RMS {:.4f} °/h\n",
                 spec.fits[f].name, model::ModelTitle(m), model::PolyPresetName(p.preset), p.runs.size(),
                 fmt::join(p.runs, ", "), p.condition_number, p.residual_rms_dph);
    }
  }
  fmt::print("\n");
}

/// Table 1's SSE_ave of the pairs, beside the paper's when the suite has them.
void PrintTable1(const validation::SuiteSpec& spec, const validation::SuiteReport& rep) {
  fmt::print("Table 1 analogue: SSE_ave (Eq. 3){}\n",
             spec.pairs_average_s > 0 ? fmt::format(" on {:g} s means, as the paper logged", spec.pairs_average_s) : "");
  fmt::print("{:<10}", "");
  for (const auto& s : rep.pairs) fmt::print(" {:>9}", s.combination.name);
  fmt::print("\n{:<10}", "rlgtherm");
  for (const auto& s : rep.pairs) fmt::print(" {:>9.4f}", s.sse_ave);
  if (!spec.paper_sse_ave.empty()) {
    fmt::print("\n{:<10}", "paper");
    for (const auto& s : rep.pairs) {
      const auto it = spec.paper_sse_ave.find(s.combination.name);
      fmt::print(" {:>9}", it == spec.paper_sse_ave.end() ? "-" : fmt::format("{:.4f}", it->second));
    }
  }
  fmt::print("\nbest: {}\n\n", model::BestPair(rep.pairs).combination.name);
}

/// Table 2: bias and stability before and after of each compensated run, with the paper's
/// columns when the suite has them; returns the run column's width, which the later tables share.
size_t PrintTable2(const validation::SuiteSpec& spec, const validation::SuiteReport& rep) {
  const auto common = compensation::CommonAveraging(rep.evaluations);
  const auto common100 = compensation::CommonAveraging(rep.evaluations, true);
  fmt::print("Table 2 analogue: bias and bias stability (1 sigma of {} means; {} in the last columns), °/h\n",
             common ? fmt::format("{:g} s", *common) : "per-run (see the checks)",
             common100 ? fmt::format("{:g} s", *common100) : "per-run");
  // The "by" column: the fit whose Eq. (2) compensated the row, or the plug-in's name. The first
  // two columns as wide as their longest entry; the paper's columns only when the suite has them.
  size_t run_width = 3, by_width = 2;
  auto by = [&](size_t i) {
    return rep.evaluation_compensator[i] == validation::kEq2 ? rep.evaluation_fit[i] : rep.evaluation_compensator[i];
  };
  for (size_t i = 0; i < rep.evaluations.size(); ++i) {
    run_width = std::max(run_width, rep.evaluations[i].run.size());
    by_width = std::max(by_width, by(i).size());
  }
  const bool paper = !spec.paper_table2.empty();
  fmt::print("{:<{}} {:<{}} {:>8} {:>8} {:>8} {:>8} | {}{:>8} {:>8} | {:>9}\n", "run", run_width, "by", by_width,
             "bias_bef", "bias_aft", "stab_bef", "stab_aft",
             paper ? fmt::format("{:>8} {:>8} {:>8} {:>8} | ", "paper", "paper", "paper", "paper") : "", "100s_bef",
             "100s_aft", "peak100");
  for (size_t i = 0; i < rep.evaluations.size(); ++i) {
    const auto& e = rep.evaluations[i];
    const bool eq2 = rep.evaluation_compensator[i] == validation::kEq2;
    const auto it = eq2 ? spec.paper_table2.find(e.run) : spec.paper_table2.end();
    std::string paper_columns;
    if (paper) {
      paper_columns = it == spec.paper_table2.end()
                          ? fmt::format("{:>8} {:>8} {:>8} {:>8} | ", "", "", "", "")
                          : fmt::format("{:>8.4f} {:>8.4f} {:>8.4f} {:>8.4f} | ", it->second[0], it->second[1],
                                        it->second[2], it->second[3]);
    }
    fmt::print("{:<{}} {:<{}} {:>8.4f} {:>8.4f} {:>8.4f} {:>8.4f} | {}{:>8.4f} {:>8.4f} | {:>9.4f}\n", e.run, run_width,
               by(i), by_width, e.bias_before_dph, e.bias_after_dph, e.stability_before.sigma, e.stability_after.sigma,
               paper_columns, e.stability_100s_before.sigma, e.stability_100s_after.sigma, e.peak_abs_100s_after_dph);
  }
  fmt::print("  peak100: the largest |100 s mean| of the compensated bias (a run's mean can hide a drift)\n");
  // Where the model was extrapolated: said where the numbers are read, as compensate says it.
  for (const auto& warnings : rep.evaluation_warnings) {
    for (const auto& w : warnings) fmt::print("  warning: {}\n", w);
  }
  for (const auto& e : rep.evaluations) {
    if (e.stability_after.adjusted() || e.stability_100s_after.adjusted()) {
      fmt::print("  {}: stability at {} and at {}\n", e.run, model::DescribeAveraging(e.stability_after, e.sample_period_s),
                 model::DescribeAveraging(e.stability_100s_after, e.sample_period_s));
    }
  }
  return run_width;
}

/// The Allan read-offs of each compensated run.
void PrintAllanReadOffs(const validation::SuiteReport& rep, size_t run_width) {
  fmt::print("\n{}", compensation::ReadOffsText(rep.evaluations, run_width));
}

/// Each check, ok or FAIL, and the count.
void PrintChecks(const validation::SuiteSpec& spec, const validation::SuiteReport& rep, size_t run_width) {
  fmt::print("\nChecks\n");
  int failed = 0;
  for (const auto& ch : rep.checks) {
    if (!ch.passed) ++failed;
    if (spec.compensators.empty()) {
      fmt::print("  {:<4} {:<14} {:<{}} {}\n", ch.passed ? "ok" : "FAIL", ch.name, ch.run, run_width, ch.detail);
    } else {
      fmt::print("  {:<4} {:<10} {:<14} {:<{}} {}\n", ch.passed ? "ok" : "FAIL", ch.compensator, ch.name, ch.run, run_width,
                 ch.detail);
    }
  }
  fmt::print("{} checks, {} failed: {}\n", rep.checks.size(), failed, rep.passed() ? "PASSED" : "FAILED");
}

int RunValidateOrThrow(const ValidateArgs& a) {
  validation::SuiteSpec spec = validation::LoadSuite(a.suite);
  if (a.seed) spec.seed = *a.seed;
  if (!spec.population && (a.gyro || !a.gyros.empty())) {
    throw InputError(fmt::format("{}: --gyro and --gyros need a population suite (a [population] table)", a.suite));
  }
  if (a.gyro && !a.gyros.empty()) throw InputError("--gyro I runs one gyro; --gyros writes the rows of all: give one");
  // A baseline that cannot be read is refused before any work.
  std::optional<nlohmann::json> baseline;
  if (!a.baseline.empty()) baseline = validation::ReadBaseline(a.baseline);
  if (spec.population && !a.gyro) return RunPopulationValidate(a, std::move(spec), baseline);
  std::optional<FigureDirectory> figures;
  if (!a.plot.empty()) figures.emplace(a.plot);
  // Steps: each run simulated, each fit, the pairs, each compensation (the model's and each
  // plug-in's), as RunSuite reports them.
  const std::vector<sim::Scenario> scenarios = a.gyro ? std::vector<sim::Scenario>{} : validation::LoadSuiteScenarios(spec);
  size_t steps = spec.fits.size() + 1;
  for (const auto& sc : scenarios) steps += sc.runs.size();
  for (const auto& fit : spec.fits) steps += fit.compensate_runs.size() * (1 + spec.compensators.size());
  Progress bar(steps, "steps");
  auto progress = [&](const std::string& what) { bar.Step(what); };
  validation::SuiteReport rep;
  nlohmann::json gyro_json;  // --gyro I: which gyro this is
  std::string gyro_text;
  if (a.gyro) {
    rep = ReportOneGyro(a, spec, gyro_json, gyro_text);
  } else {
    rep = validation::RunSuite(spec, scenarios, nullptr, std::nullopt, progress);
  }
  bar.Done();
  // The report as --json prints it: the baseline is compared with it, as it will be with the next.
  nlohmann::json j = SuiteReportJson(spec, rep);
  if (a.gyro) j["gyro"] = gyro_json;
  std::optional<validation::BaselineReport> regression;
  if (baseline) regression = validation::CompareWithBaseline(j, *baseline, a.baseline, spec.baseline_max_sigma);
  const bool passed = rep.passed() && (!regression || regression->passed());
  const int status = passed ? 0 : 4;
  if (figures) DrawSuiteFigures(*figures, spec, rep);  // staged: committed once the other outputs are written
  if (!a.junit.empty()) {
    validation::SuiteReport junit;  // the checks alone: all SuiteJunitXml reads
    junit.checks = rep.checks;
    if (regression) AppendChecks(junit.checks, validation::BaselineChecks(*regression));
    WriteText(a.junit, validation::SuiteJunitXml(junit, std::filesystem::path(a.suite).stem().string()));
  }
  if (figures) figures->Commit();
  if (a.json) {
    if (regression) j["baseline"] = validation::BaselineJson(*regression);
    j["passed"] = passed;
    fmt::print("{}\n", j.dump(2));
    return status;
  }

  fmt::print("{}", gyro_text);
  PrintFits(spec, rep);
  PrintTable1(spec, rep);
  const size_t run_width = PrintTable2(spec, rep);
  PrintAllanReadOffs(rep, run_width);
  PrintChecks(spec, rep, run_width);
  if (regression) fmt::print("{}", validation::BaselineText(*regression));
  return status;
}

}  // namespace

Verb RegisterValidate(CLI::App& app) {
  auto a = std::make_shared<ValidateArgs>();
  CLI::App* cmd = app.add_subcommand("validate", "end to end: simulate -> fit -> compensate -> checks");
  cmd->add_option("SUITE", a->suite, "suite TOML file")->required();
  cmd->add_flag("--json", a->json, "machine-readable output");
  cmd->add_option("--seed", a->seed,
                  "random seed for every scenario (default: the suite's 'seed', else each scenario's)");
  cmd->add_option("--junit", a->junit, "also write the checks as JUnit XML to this file (docs/data-format.md)");
  cmd->add_option("--plot", a->plot,
                  "directory for figures: table1.png, and bias_<run>.png and "
                  "allan_<run>.png of each compensated run");
  cmd->add_option("--threads", a->threads,
                  "population suites: gyros in parallel on N threads "
                  "(default 0: one per core; the output does not depend on it)")
      ->check(CLI::Range(0, 1024));
  cmd->add_option("--gyros", a->gyros,
                  "population suites: write one CSV row per gyro (its id, seed, "
                  "drawn parameters and metrics) to this file");
  cmd->add_option("--gyro", a->gyro,
                  "population suites: run gyro I alone and print its one-gyro "
                  "report (the same numbers as its row in --gyros)");
  cmd->add_option("--baseline", a->baseline,
                  "a previous --json of the suite: compare each metric with it "
                  "against their noise; exit 4 when one regressed (docs/cli.md)");
  return {cmd, [a] { return RunValidate(*a); }};
}

}  // namespace rlg::cli
