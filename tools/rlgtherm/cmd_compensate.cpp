// Verbs compensate (the paper's Table 2 analogue, in batch or streaming, with any model's
// coefficient file) and evaluate (the same table for a compensated column of any origin), through
// one report (compensation/evaluation_report.h).

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "compensation/compensator.h"
#include "compensation/evaluation.h"
#include "compensation/evaluation_report.h"
#include "compensation/model_compensator.h"
#include "compensation/stream.h"
#include "io/atomic_output.h"
#include "io/checked_stream.h"
#include "model/coefficients_json.h"
#include "sim/errors.h"
#include "tools/rlgtherm/commands.h"
#include "tools/rlgtherm/common.h"
#include "tools/rlgtherm/verb_figures.h"

namespace rlg::cli {
namespace {

/// CSV in (file or stdin), compensated CSV out on stdout, one row at a time.
int Stream(const CompensateArgs& a, const model::FittedModel& c) {
  std::ifstream file;
  if (a.data != "-") {
    file.open(a.data);
    if (!file) throw InputError(fmt::format("{}: cannot open data file", a.data));
  }
  std::istream& in = a.data == "-" ? std::cin : file;
  io::CsvRowReader reader(in, a.data == "-" ? "<stdin>" : a.data, compensation::StreamReadOptions(a.column));
  for (const auto& w : reader.warnings()) fmt::print(stderr, "rlgtherm: warning: {}\n", w);
  io::StdoutStream out;
  compensation::StreamOptions options;
  options.bias_column = a.column;
  options.data_name = a.data;
  options.after_row = [&] { out.Check(); };  // stop at the first row that cannot be written
  compensation::CompensateStream(c, reader, out.stream(), options);
  return 0;
}

/// The report on stdout, as JSON or as the text table (the same for compensate and evaluate).
int PrintEvaluationReport(const compensation::EvaluationReport& report, bool json) {
  if (json) {
    fmt::print("{}\n", compensation::EvaluationReportJson(report).dump(2));
  } else {
    fmt::print("{}", compensation::EvaluationReportText(report));
  }
  return 0;
}

/// --plot of compensate and evaluate: per run, the bias before and after and the Allan curve
/// of the compensated bias the report read its terms from.
void DrawEvaluationFigures(FigureDirectory& figures, const sim::Trace& trace,
                           const compensation::EvaluationReport& report) {
  for (const auto& e : report.runs) {
    const sim::Run& run = trace.FindRun(e.run);
    figures.WriteBias(run, run.Column(report.bias_column), report.bias_column, run.Column(report.compensated_column),
                      report.compensated_column);
    figures.WriteAllan(e.run, report.compensated_column, e.allan, e.noise);
  }
}

}  // namespace

int RunCompensate(const CompensateArgs& a) {
  if (a.stream && a.from_s) {
    throw InputError("--from: compensate --stream writes each row as it comes and keeps no report to cut; use --from "
                     "without --stream");
  }
  if (a.stream && !a.plot.empty()) {
    throw InputError("--plot: compensate --stream keeps no report to draw (it writes each row as it comes); "
                     "use --plot without --stream");
  }
  // The figure directory first: an unusable DIR is refused before any work.
  std::optional<FigureDirectory> figures;
  if (!a.plot.empty()) figures.emplace(a.plot);
  const model::FittedModel c = model::ReadModelFile(a.coeffs);  // any model of the family
  if (a.stream) return Stream(a, c);
  const bool raw = a.column == "bias_dph";
  sim::Trace trace = LoadData(a.data, raw, raw ? std::vector<std::string>{} : std::vector<std::string>{a.column});
  compensation::EvaluationOptions options;
  options.averaging_s = a.averaging_s;
  options.averaging_explicit = a.averaging_explicit;
  options.bias_column = a.column;
  const std::string out_column = compensation::AddCompensatedColumn(c, trace, a.column);
  // --from: every run compensated from its power-on, Table 2 of its samples from the cut on.
  sim::Trace scored;
  if (a.from_s) {
    if (!(*a.from_s >= 0.0)) throw InputError(fmt::format("--from {:g}: expected a time (s) >= 0", *a.from_s));
    scored.source = trace.source;
    for (const auto& r : trace.runs) {
      scored.runs.push_back(sim::Tail(r, sim::FirstSampleAt(r, *a.from_s)));
      if (scored.runs.back().size() < 2) {
        throw InputError(fmt::format("{}: --from {:g} s leaves fewer than two samples to score", r.Where(), *a.from_s));
      }
    }
  }
  const compensation::EvaluationReport report =
      compensation::EvaluateTrace(a.from_s ? scored : trace, out_column, options, c);
  for (const auto& w : report.warnings) fmt::print(stderr, "rlgtherm: warning: {}\n", w);
  if (figures) DrawEvaluationFigures(*figures, a.from_s ? scored : trace, report);
  if (!a.out.empty()) io::WriteFileAtomically(a.out, [&](std::ostream& out) { io::WriteTraceCsv(trace, out); });
  if (figures) figures->Commit();
  if (a.out == "-") return 0;
  return PrintEvaluationReport(report, a.json);
}

int RunEvaluate(const EvaluateArgs& a) {
  std::optional<FigureDirectory> figures;
  if (!a.plot.empty()) figures.emplace(a.plot);
  std::vector<std::string> keep{a.compensated};
  if (a.column != "bias_dph") keep.push_back(a.column);
  const sim::Trace trace = LoadData(a.data, a.column == "bias_dph", keep);
  compensation::EvaluationOptions options;
  options.averaging_s = a.averaging_s;
  options.averaging_explicit = a.averaging_explicit;
  options.bias_column = a.column;
  options.trend_channel = a.trend_channel;
  options.b0_window_s = a.b0_window_s;
  const compensation::EvaluationReport report = compensation::EvaluateTrace(trace, a.compensated, options);
  if (figures) {
    DrawEvaluationFigures(*figures, trace, report);
    figures->Commit();
  }
  return PrintEvaluationReport(report, a.json);
}

Verb RegisterCompensate(CLI::App& app) {
  auto a = std::make_shared<CompensateArgs>();
  CLI::App* cmd = app.add_subcommand("compensate", "Table 2: bias and stability before/after causal compensation");
  cmd->add_option("DATA", a->data, "tidy CSV ('-' = stdin)")->required();
  cmd->add_option("--coeffs", a->coeffs, "coefficients JSON from 'fit'")->required();
  cmd->add_option("-o,--output", a->out, "write the data with a bias_comp_dph column ('-' = stdout)");
  auto* averaging = cmd->add_option("--averaging", a->averaging_s,
                                    "averaging time (s) of the stability columns: whole samples, at least one "
                                    "(the default 1 s is raised to the sample period of coarser data, saying so)")
                        ->capture_default_str();
  cmd->add_option("--column", a->column, "bias column to compensate and evaluate (°/h)")->capture_default_str();
  cmd->add_option("--from", a->from_s,
                  "Table 2 of each run's samples from this time on (s after its first "
                  "sample), compensated from its power-on (the part a fit --until left out)");
  cmd->add_flag("--stream", a->stream, "sample by sample: read rows and write each compensated row to stdout at once");
  cmd->add_flag("--json", a->json, "machine-readable output (keys: docs/data-format.md)");
  cmd->add_option("--plot", a->plot,
                  "directory for figures: bias_<run>.png (before/after, temperatures) and "
                  "allan_<run>.png (compensated bias); not with --stream");
  return {cmd, [a, averaging] {
            a->averaging_explicit = averaging->count() > 0;
            return RunCompensate(*a);
          }};
}

Verb RegisterEvaluate(CLI::App& app) {
  auto a = std::make_shared<EvaluateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "evaluate",
      "Table 2 for a compensated column of your own: bias and stability before/after, trend, Allan read-offs");
  cmd->add_option("DATA", a->data, "tidy CSV ('-' = stdin) holding the raw and the compensated bias")->required();
  cmd->add_option("--compensated", a->compensated, "the compensated bias column (°/h)")->required();
  cmd->add_option("--column", a->column, "the raw bias column (°/h)")->capture_default_str();
  auto* eval_averaging =
      cmd->add_option("--averaging", a->averaging_s, "averaging time (s) of the stability columns (as for compensate)")
          ->capture_default_str();
  cmd->add_option("--trend-channel", a->trend_channel, "temperature the residual trend is regressed on")
      ->capture_default_str();
  cmd->add_option("--b0-window", a->b0_window_s, "window (s) whose mean's error is reported as b0_error_dph")
      ->capture_default_str();
  cmd->add_flag("--json", a->json, "machine-readable output, the keys of compensate --json (docs/data-format.md)");
  cmd->add_option("--plot", a->plot, "directory for figures: bias_<run>.png and allan_<run>.png (as compensate)");
  return {cmd, [a, eval_averaging] {
            a->averaging_explicit = eval_averaging->count() > 0;
            return RunEvaluate(*a);
          }};
}

}  // namespace rlg::cli
