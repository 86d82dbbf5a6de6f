// Verbs diagnose and import.

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "model/diagnose.h"
#include "model/diagnosis_report.h"
#include "sim/csv.h"
#include "sim/errors.h"
#include "sim/import.h"
#include "sim/output_file.h"
#include "tools/rlgtherm/commands.h"
#include "tools/rlgtherm/common.h"
#include "tools/rlgtherm/report_figures.h"

namespace rlg::cli {
namespace {

/// The channel whose temperature the bias residuals are plotted against: the sensor on the
/// bias node (T1, block, in the default gyro), else the first sensor.
std::string BiasTemperatureChannel(const sim::GyroConfig& g) {
  for (const auto& s : g.sensors)
    if (s.node == g.bias.node) return s.channel;
  return g.sensors.front().channel;
}

/// Writes the report files into `report`'s staging directory and commits them together: a
/// report is whole or absent. Returns the file names.
std::vector<std::string> WriteReport(sim::OutputDirectory& report, const model::Diagnosis& d, const std::string& gyro_path,
                                     const sim::GyroConfig& gyro, double score_block_s, const nlohmann::json& j) {
  auto text_file = [&](const std::string& name, const std::string& text) {
    report.Write(name, [&](std::ostream& out) { out << text; });
  };
  text_file("diagnosis.json", j.dump(2) + "\n");
  // Residual traces: one tidy file of block means; per channel the data, its rate (temperature
  // channels) and the residual measured - simulated of the baseline and of the extended model.
  std::string csv = "run,t_s";
  std::vector<std::string> channels;
  for (const auto& [ch, v] : d.residuals.front().measured) channels.push_back(ch);
  for (const auto& ch : channels) {
    csv += ",measured_" + ch;
    if (ch != "bias_dph") csv += ",dTdt_" + ch + "_C_per_min";
    csv += ",baseline_" + ch + ",extended_" + ch;
  }
  csv += "\n";
  for (const auto& tr : d.residuals) {
    std::map<std::string, std::vector<double>> rate;
    for (const auto& [ch, m] : tr.measured)
      if (ch != "bias_dph") rate[ch] = RatePerMinute(tr.t_s, m);
    for (size_t k = 0; k < tr.t_s.size(); ++k) {
      csv += fmt::format("{},{:.3f}", tr.run, tr.t_s[k]);
      for (const auto& ch : channels) {
        const auto m = tr.measured.find(ch), b = tr.baseline.find(ch), e = tr.extended.find(ch);
        const bool has = m != tr.measured.end() && k < b->second.size();
        csv += has ? fmt::format(",{:.8g}", m->second[k]) : ",";
        if (ch != "bias_dph") csv += has ? fmt::format(",{:.6g}", rate[ch][k]) : ",";
        csv += has ? fmt::format(",{:.6g},{:.6g}", b->second[k], e->second[k]) : ",,";
      }
      csv += "\n";
    }
  }
  text_file("residuals.csv", csv);
  // The extended gyro: the nominal file plus the accepted effects, runnable by `simulate`.
  std::ifstream in(gyro_path);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad() || text.empty()) throw InputError(fmt::format("{}: cannot read the gyro file again for extended-gyro.toml", gyro_path));
  text += "\n# ---- added by rlgtherm diagnose ----\n# calibrated knobs (not applied here; the nominal values above stay):\n";
  for (const auto& [k, v] : d.calibrated) text += fmt::format("#   {} = {:.6g}\n", k, v);
  for (const auto& s : d.steps) {
    if (s.accepted.cause == "bias.hysteresis") {
      text += fmt::format("\n[[effects]]\nname = \"{}\"\ntarget = \"{}\"\nk_heating_dph_per_C = {:.6g}\nk_cooling_dph_per_C = 0.0\n",
                          s.accepted.cause, s.accepted.target, s.accepted.parameters.at("k_heating_minus_cooling_dph_per_C"));
      continue;
    }
    text += fmt::format("\n[[effects]]\nname = \"{}\"\ntarget = \"{}\"\n", s.accepted.cause, s.accepted.target);
    for (const auto& [k, v] : s.accepted.parameters) text += fmt::format("{} = {:.6g}\n", k, v);
  }
  text_file("extended-gyro.toml", text);
  WriteDiagnosisFigures(report, d, BiasTemperatureChannel(gyro), score_block_s);
  return report.Commit();
}

}  // namespace

int RunDiagnose(const DiagnoseArgs& a) {
  // The report directory first: an unusable --report is refused before minutes of work.
  std::optional<sim::OutputDirectory> report;
  if (!a.report.empty()) report.emplace(a.report);
  const sim::Trace data = LoadData(a.data, /*require_bias=*/false);
  const sim::GyroConfig gyro = sim::LoadGyro(a.gyro);
  model::DiagnoseOptions o;
  o.max_steps = a.max_steps;
  o.fit_runs = a.fit_runs;
  o.per_run_source_gains = a.per_run_gains;
  const model::Diagnosis d = model::Diagnose(data, gyro, o);
  const nlohmann::json j = model::DiagnosisJson(d);
  std::vector<std::string> report_files;
  if (report) report_files = WriteReport(*report, d, a.gyro, gyro, d.score_block_s.second, j);
  if (a.json) {
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  model::DiagnosisTextOptions text;
  text.data_name = a.data;
  text.gyro_name = a.gyro;
  fmt::print("{}", model::DiagnosisText(d, text));
  if (!a.report.empty()) fmt::print("\nreport in {}: {}\n", a.report, fmt::join(report_files, ", "));
  return 0;
}

int RunImport(const ImportArgs& a) {
  if (a.format != "tclab") throw InputError(fmt::format("import: unknown format '{}'; known: tclab", a.format));
  sim::Trace trace;
  trace.comments.push_back("imported by rlgtherm import tclab; heater power = drive % x nominal gain (1e-2, 7.5e-3 W/%)");
  for (const auto& f : a.files) trace.runs.push_back(sim::ImportTclab(f));
  sim::WriteFileAtomically(a.out, [&](std::ostream& out) { sim::WriteTraceCsv(trace, out); });
  if (a.out != "-") {
    for (const auto& r : trace.runs)
      fmt::print("{}: {} samples, {:g} s\n", r.id, r.size(), r.t_s.back());
  }
  return 0;
}

}  // namespace rlg::cli
