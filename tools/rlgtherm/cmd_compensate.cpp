// Verb compensate: the paper's Table 2 analogue, in batch or streaming.

#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "compensation/compensator.h"
#include "compensation/evaluation.h"
#include "compensation/stream.h"
#include "model/coefficients_json.h"
#include "sim/errors.h"
#include "sim/output_file.h"
#include "tools/rlgtherm/commands.h"
#include "tools/rlgtherm/common.h"

namespace rlg::cli {
namespace {

/// CSV in (file or stdin), compensated CSV out on stdout, one row at a time.
int Stream(const CompensateArgs& a, const model::Guo2006Coefficients& c) {
  std::ifstream file;
  if (a.data != "-") {
    file.open(a.data);
    if (!file) throw InputError(fmt::format("{}: cannot open data file", a.data));
  }
  std::istream& in = a.data == "-" ? std::cin : file;
  sim::CsvRowReader reader(in, a.data == "-" ? "<stdin>" : a.data, compensation::StreamReadOptions(a.column));
  for (const auto& w : reader.warnings()) fmt::print(stderr, "rlgtherm: warning: {}\n", w);
  sim::StdoutStream out;
  compensation::StreamOptions options;
  options.bias_column = a.column;
  options.data_name = a.data;
  options.after_row = [&] { out.Check(); };  // stop at the first row that cannot be written
  compensation::CompensateStream(c, reader, out.stream(), options);
  return 0;
}

}  // namespace

int RunCompensate(const CompensateArgs& a) {
  const model::Guo2006Coefficients c = model::ReadCoefficientsFile(a.coeffs);
  if (a.stream) return Stream(a, c);
  const bool raw = a.column == "bias_dph";
  sim::Trace trace = LoadData(a.data, raw, raw ? std::vector<std::string>{} : std::vector<std::string>{a.column});
  compensation::EvaluationOptions options;
  options.averaging_s = a.averaging_s;
  options.averaging_explicit = a.averaging_explicit;
  options.bias_column = a.column;
  const std::string out_column = compensation::CompensatedColumnName(a.column);
  std::vector<compensation::RunEvaluation> evals;
  for (auto& run : trace.runs) {
    std::vector<double> comp = compensation::CompensateRun(c, run, a.column);  // refuses a run shorter than B0's window
    evals.push_back(AtRun(run, [&] { return compensation::EvaluateRun(run, comp, c, options); }));
    if (evals.back().outside_fitted_range) {
      fmt::print(stderr, "rlgtherm: warning: {}: Ti0 = {:.2f} °C is outside the fitted range {:.2f} ... {:.2f} °C\n",
                 run.Where(), evals.back().Ti0_C, c.t10_range_C[0], c.t10_range_C[1]);
    }
    run.AddColumn(out_column) = std::move(comp);
  }
  if (!a.out.empty()) sim::WriteFileAtomically(a.out, [&](std::ostream& out) { sim::WriteTraceCsv(trace, out); });
  if (a.out == "-") return 0;
  const auto common = compensation::CommonAveraging(evals);
  const auto common100 = compensation::CommonAveraging(evals, true);
  if (a.json) {
    nlohmann::json j;
    // The averaging time the stabilities were computed at (null when it differs between runs:
    // see each run's stability_averaging_s); the one asked for beside it.
    j["averaging_s"] = common ? nlohmann::json(*common) : nlohmann::json(nullptr);
    j["averaging_requested_s"] = a.averaging_s;
    j["column"] = a.column;
    j["runs"] = nlohmann::json::array();
    for (const auto& e : evals) j["runs"].push_back(compensation::EvaluationJson(e));
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  fmt::print("Compensation of {} with pair ({}, {}); bias stability = 1 sigma of consecutive {}\n", a.column, c.pair[0],
             c.pair[1],
             common && common100 ? fmt::format("{:g} s and {:g} s means", *common, *common100)
                                 : "means, over the averaging times listed per run:");
  std::vector<std::string> notes;
  for (const auto& e : evals) {
    for (const auto* s : {&e.stability_after, &e.stability_100s_after}) {
      if (!s->adjusted() && common && common100) continue;
      const std::string note = (common && common100 ? "stability at " : e.run + ": stability at ") +
                               model::DescribeAveraging(*s, e.sample_period_s);
      if (std::find(notes.begin(), notes.end(), note) == notes.end()) notes.push_back(note);
    }
  }
  for (const auto& note : notes) fmt::print("  {}\n", note);
  fmt::print("{:<12} {:>9} {:>9} {:>9} {:>9} {:>10} {:>10} {:>16} {:>9}\n", "run", "bias_bef", "bias_aft", "stab_bef",
             "stab_aft", "stab100_b", "stab100_a", "trend °/h/°C", "B0 err");
  for (const auto& e : evals) {
    fmt::print("{:<12} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>10.4f} {:>10.4f} {:>+9.4f}±{:<6.4f} {:>9.4f}\n", e.run,
               e.bias_before_dph, e.bias_after_dph, e.stability_before.sigma, e.stability_after.sigma,
               e.stability_100s_before.sigma, e.stability_100s_after.sigma, e.trend_dph_per_C, e.trend_stderr_dph_per_C,
               e.b0_error_dph);
  }
  return 0;
}

}  // namespace rlg::cli
