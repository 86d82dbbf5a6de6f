// Verb compensate: the paper's Table 2 analogue, in batch or streaming.

#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "compensation/compensator.h"
#include "compensation/evaluation.h"
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
  sim::CsvRowReader reader(in, a.data == "-" ? "<stdin>" : a.data);
  for (const auto& w : reader.warnings()) fmt::print(stderr, "rlgtherm: warning: {}\n", w);
  sim::CsvRow row;
  // A file without data rows is refused as in batch mode (same check first, same message),
  // before anything goes out.
  if (!reader.Next(row)) sim::ThrowNoDataRows(a.data == "-" ? "<stdin>" : a.data, reader.line());
  const auto& names = reader.names();
  auto index = [&](const std::string& name) {
    const auto it = std::find(names.begin(), names.end(), name);
    if (it == names.end()) throw InputError(fmt::format("{}: no column '{}' (the coefficients use pair {},{})", a.data, name, c.pair[0], c.pair[1]));
    return static_cast<size_t>(it - names.begin());
  };
  const size_t i = index(c.pair[0]), j = index(c.pair[1]), b = index("bias_dph");
  std::vector<std::string> out_names = names;
  out_names.push_back("bias_comp_dph");
  sim::StdoutStream out;
  sim::CsvRowWriter writer(out.stream(), out_names, reader.comments());
  compensation::Compensator comp(c);
  std::vector<double> values(out_names.size());
  do {
    if (row.new_run) comp.Reset();
    std::copy(row.values.begin(), row.values.end(), values.begin());
    values.back() = comp.Update(row.t_s, row.values[i], row.values[j], row.values[b]);
    writer.Write(row.run, row.t_s, values.data());
    writer.Flush();  // a gyro computer's consumer wants each sample as it comes
    out.Check();     // and stops at the first row that cannot be written
  } while (reader.Next(row));
  return 0;
}

}  // namespace

int RunCompensate(const CompensateArgs& a) {
  const model::Guo2006Coefficients c = model::ReadCoefficientsFile(a.coeffs);
  if (a.stream) return Stream(a, c);
  sim::Trace trace = LoadData(a.data);
  std::vector<compensation::RunEvaluation> evals;
  for (auto& run : trace.runs) {
    model::InitialBias(run, c.b0_window_s);  // InputError if the run is shorter than the B0 window
    std::vector<double> comp = compensation::CompensateRun(c, run);
    evals.push_back(AtRun(run, [&] { return compensation::EvaluateRun(run, comp, c, a.averaging_s); }));
    if (evals.back().outside_fitted_range) {
      fmt::print(stderr, "rlgtherm: warning: {}: Ti0 = {:.2f} °C is outside the fitted range {:.2f} ... {:.2f} °C\n",
                 run.Where(), evals.back().Ti0_C, c.t10_range_C[0], c.t10_range_C[1]);
    }
    run.AddColumn("bias_comp_dph") = std::move(comp);
  }
  if (!a.out.empty()) sim::WriteFileAtomically(a.out, [&](std::ostream& out) { sim::WriteTraceCsv(trace, out); });
  if (a.out == "-") return 0;
  if (a.json) {
    nlohmann::json j;
    j["averaging_s"] = a.averaging_s;
    j["runs"] = nlohmann::json::array();
    for (const auto& e : evals) j["runs"].push_back(EvaluationJson(e));
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  fmt::print("Compensation with pair ({}, {}); bias stability = 1 sigma of consecutive {:g} s and 100 s means\n",
             c.pair[0], c.pair[1], a.averaging_s);
  fmt::print("{:<12} {:>9} {:>9} {:>9} {:>9} {:>10} {:>10} {:>16} {:>9}\n", "run", "bias_bef", "bias_aft", "stab_bef",
             "stab_aft", "stab100_b", "stab100_a", "trend °/h/°C", "B0 err");
  for (const auto& e : evals) {
    fmt::print("{:<12} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>10.4f} {:>10.4f} {:>+9.4f}±{:<6.4f} {:>9.4f}\n", e.run,
               e.bias_before_dph, e.bias_after_dph, e.stability_before_dph, e.stability_after_dph,
               e.stability_100s_before_dph, e.stability_100s_after_dph, e.trend_dph_per_C, e.trend_stderr_dph_per_C,
               e.b0_error_dph);
  }
  return 0;
}

}  // namespace rlg::cli
