// Verbs compensate (the paper's Table 2 analogue, in batch or streaming, with any model's
// coefficient file) and evaluate (the same table for a compensated column of any origin), through
// one report (compensation/evaluation_report.h).

#include <fmt/format.h>
#include <fstream>
#include <iostream>
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

}  // namespace rlg::cli
