// Verbs diagnose and import.

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "model/diagnose.h"
#include "sim/csv.h"
#include "sim/errors.h"
#include "sim/import.h"
#include "sim/output_file.h"
#include "tools/rlgtherm/commands.h"
#include "tools/rlgtherm/common.h"
#include "tools/rlgtherm/report_figures.h"

namespace rlg::cli {
namespace {

nlohmann::json MetricsJson(const model::Metrics& m, bool bias) {
  nlohmann::json j;
  if (bias) j["bias_rms_dph"] = m.bias_rms_dph;
  j["temperature_rms_C"] = m.temperature_rms_C;
  return j;
}

nlohmann::json CandidateJson(const model::Candidate& c) {
  return {{"cause", c.cause}, {"target", c.target}, {"score", c.score}, {"heldout_rms_ratio", c.heldout_rms_ratio},
          {"parameters", c.parameters}, {"kind", c.kind}};
}

/// The averaging time of the report's RMS values, as computed: "100 s", or "99-100 s" when
/// runs of different sample periods hold different whole numbers of samples.
std::string ScoreBlockText(const model::Diagnosis& d) {
  // Three digits, compared as printed: 1000 samples of 0.1 s are not 100.0 s to the last bit.
  const std::string lo = fmt::format("{:.3g}", d.score_block_s.first), hi = fmt::format("{:.3g}", d.score_block_s.second);
  return lo == hi ? lo + " s" : lo + "-" + hi + " s";
}

nlohmann::json ReportJson(const model::Diagnosis& d) {
  nlohmann::json j;
  const bool none = d.steps.empty();
  j["cause"] = none ? "none" : d.steps.front().accepted.cause;
  j["target"] = none ? "" : d.steps.front().accepted.target;
  j["parameters"] = none ? nlohmann::json::object() : nlohmann::json(d.steps.front().accepted.parameters);
  j["baseline"] = MetricsJson(d.baseline, d.has_bias);
  j["extended"] = MetricsJson(none ? d.baseline : d.extended, d.has_bias);
  const double ratio = none ? 1.0
                            : (d.has_bias && d.extended.bias_rms_dph > 0.0 && d.steps.front().accepted.kind == "bias"
                                   ? d.baseline.bias_rms_dph / d.extended.bias_rms_dph
                                   : d.steps.front().accepted.heldout_rms_ratio);
  double stability = 1.0;
  for (const auto& s : d.steps) stability *= s.compensated_stability_ratio;
  j["gain"] = {{"heldout_rms_ratio", ratio}, {"compensated_stability_ratio", stability}};
  j["candidates"] = nlohmann::json::array();
  for (const auto& c : d.first_candidates) j["candidates"].push_back(CandidateJson(c));
  j["accepted"] = nlohmann::json::array();
  for (const auto& s : d.steps) {
    nlohmann::json a = CandidateJson(s.accepted);
    a["compensated_stability_ratio"] = s.compensated_stability_ratio;
    a["before"] = MetricsJson(s.before, d.has_bias);
    a["after"] = MetricsJson(s.after, d.has_bias);
    a["notes"] = s.notes;
    j["accepted"].push_back(a);
  }
  j["calibrated"] = d.calibrated;
  j["identifiability"] = d.identifiability;
  nlohmann::json corr = nlohmann::json::object();
  for (size_t a = 0; a < d.knob_names.size(); ++a)
    for (size_t b = 0; b < d.knob_names.size(); ++b)
      corr[d.knob_names[a]][d.knob_names[b]] = d.knob_correlations(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
  j["parameter_correlations"] = corr;
  j["ljung_box_p"] = d.ljung_box_p;
  j["score_block_s"] = {{"min", d.score_block_s.first}, {"max", d.score_block_s.second}};
  j["notes"] = d.notes;
  return j;
}

/// The knob pairs whose posterior correlation (log units) is at least `min_abs` in size,
/// strongest first, at most `n`.
std::vector<std::string> StrongCorrelations(const model::Diagnosis& d, double min_abs, size_t n) {
  std::vector<std::pair<double, std::string>> pairs;
  for (size_t a = 0; a < d.knob_names.size(); ++a) {
    for (size_t b = a + 1; b < d.knob_names.size(); ++b) {
      const double r = d.knob_correlations(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
      if (std::abs(r) >= min_abs) pairs.emplace_back(-std::abs(r), fmt::format("{} ~ {} {:+.2f}", d.knob_names[a], d.knob_names[b], r));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<std::string> out;
  for (size_t i = 0; i < std::min(n, pairs.size()); ++i) out.push_back(pairs[i].second);
  return out;
}

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
  const nlohmann::json j = ReportJson(d);
  std::vector<std::string> report_files;
  if (report) report_files = WriteReport(*report, d, a.gyro, gyro, d.score_block_s.second, j);
  if (a.json) {
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  fmt::print("Diagnosis of {} against {} ({} data)\n", a.data, a.gyro, d.has_bias ? "bias and temperature" : "thermal-only");
  fmt::print("Baseline (calibrated nominal), held-out RMS on {} means:", ScoreBlockText(d));
  for (const auto& [ch, v] : d.baseline.temperature_rms_C) fmt::print(" {} {:.4f} °C", ch, v);
  if (d.has_bias) fmt::print(", bias {:.4f} °/h", d.baseline.bias_rms_dph);
  fmt::print("\n");
  for (const auto& [ch, p] : d.ljung_box_p) fmt::print("  Ljung-Box p ({} residuals, 10 lags): {:.3g}\n", ch, p);
  for (const auto& note : d.identifiability) fmt::print("  identifiability: {}\n", note);
  for (const auto& pair : StrongCorrelations(d, 0.8, 5)) fmt::print("  posterior correlation: {}\n", pair);
  for (const auto& note : d.notes) fmt::print("  {}\n", note);
  fmt::print("\nCandidates of the first search (best first):\n");
  for (size_t i = 0; i < std::min<size_t>(8, d.first_candidates.size()); ++i) {
    const auto& c = d.first_candidates[i];
    fmt::print("  {:<24} {:<18} score {:>10.1f}  held-out RMS ratio {:.3f}\n", c.cause, c.target, c.score, c.heldout_rms_ratio);
  }
  if (d.steps.empty()) fmt::print("\ncause: none (no candidate is significant)\n");
  for (size_t i = 0; i < d.steps.size(); ++i) {
    const auto& s = d.steps[i];
    fmt::print("\nstep {}: {} on {}", i + 1, s.accepted.cause, s.accepted.target);
    for (const auto& [k, v] : s.accepted.parameters) fmt::print(", {} = {:.5g}", k, v);
    fmt::print("\n  held-out RMS ratio {:.3f}", s.accepted.heldout_rms_ratio);
    if (s.accepted.kind == "bias") fmt::print(", compensated {} stability ratio {:.3f}", ScoreBlockText(d), s.compensated_stability_ratio);
    fmt::print("\n  held-out RMS before -> after:");
    for (const auto& [ch, v] : s.before.temperature_rms_C) fmt::print(" {} {:.4f} -> {:.4f} °C", ch, v, s.after.temperature_rms_C.at(ch));
    if (d.has_bias) fmt::print(", bias {:.4f} -> {:.4f} °/h", s.before.bias_rms_dph, s.after.bias_rms_dph);
    fmt::print("\n");
    for (const auto& n : s.notes) fmt::print("  note: {}\n", n);
  }
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
