// Verbs diagnose and import.

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <unistd.h>

#include "diagnosis/diagnose.h"
#include "diagnosis/report.h"
#include "io/atomic_output.h"
#include "io/csv.h"
#include "io/gyro_file.h"
#include "io/gyro_toml.h"
#include "io/import.h"
#include "sim/errors.h"
#include "tools/rlgtherm/commands.h"
#include "tools/rlgtherm/common.h"
#include "tools/rlgtherm/report_figures.h"

namespace rlg::cli {
namespace {

/// residuals.csv: the library's table, times to the millisecond, the data to 8 significant
/// digits, rates and residuals to 6; absent cells empty.
std::string ResidualsCsv(const diagnosis::ResidualTable& table) {
  std::string csv = "run,t_s";
  for (const auto& c : table.columns) csv += "," + c.name;
  csv += "\n";
  for (const auto& run : table.runs) {
    for (size_t k = 0; k < run.t_s.size(); ++k) {
      csv += fmt::format("{},{:.3f}", run.run, run.t_s[k]);
      for (size_t c = 0; c < table.columns.size(); ++c) {
        const std::vector<double>& v = run.values[c];
        if (k >= v.size()) csv += ",";
        else if (table.columns[c].kind == diagnosis::ResidualColumn::Kind::kMeasured) csv += fmt::format(",{:.8g}", v[k]);
        else csv += fmt::format(",{:.6g}", v[k]);
      }
      csv += "\n";
    }
  }
  return csv;
}

/// Writes the report files into `report`'s staging directory and commits them together: a
/// report is whole or absent. `extended_gyro`: the calibrated nominal plus the accepted
/// effects, the gyro the diagnosis scored (Diagnosis::extended_gyro); none without a gyro file.
/// Returns the file names.
std::vector<std::string> WriteReport(io::OutputDirectory& report, const diagnosis::SearchRecord& d,
                                     const sim::GyroConfig* extended_gyro, const std::string& bias_temperature,
                                     const nlohmann::json& j) {
  auto text_file = [&](const std::string& name, const std::string& text) {
    report.Write(name, [&](std::ostream& out) { out << text; });
  };
  text_file("diagnosis.json", j.dump(2) + "\n");
  text_file("residuals.csv", ResidualsCsv(diagnosis::MakeResidualTable(d)));
  // The extended gyro as a gyro file `simulate` runs.
  if (extended_gyro)
    report.Write("extended-gyro.toml", [&](std::ostream& out) { io::WriteGyroToml(*extended_gyro, out); });
  WriteDiagnosisFigures(report, diagnosis::MakeDiagnosisFigures(d, bias_temperature));
  return report.Commit();
}

}  // namespace

int RunDiagnose(const DiagnoseArgs& a) {
  // The report directory first: an unusable --report is refused before minutes of work.
  std::optional<io::OutputDirectory> report;
  if (!a.report.empty()) report.emplace(a.report);
  const sim::Trace data = LoadData(a.data, /*require_bias=*/false);
  // Without a gyro file: the bias search alone over the measured channels.
  std::optional<sim::GyroConfig> gyro;
  if (!a.gyro.empty()) gyro = io::LoadGyro(a.gyro);
  diagnosis::DiagnoseOptions o;
  o.max_steps = a.max_steps;
  o.lookahead = a.lookahead;
  o.fit_runs = a.fit_runs;
  o.per_run_source_gains = a.per_run_gains;
  o.power = a.power;
  // Progress on stderr when it is a terminal (docs/cli.md), one line rewritten in place.
  const bool tty = ::isatty(STDERR_FILENO);
  if (tty) o.progress = [](const std::string& what) { fmt::print(stderr, "\rdiagnose: {}\x1b[K", what); };
  struct ClearLine {  // also when Diagnose throws, so that its message starts a clean line
    bool tty;
    ~ClearLine() {
      if (tty) fmt::print(stderr, "\r\x1b[K");
    }
  };
  std::optional<diagnosis::Diagnosis> network;             // with a gyro file
  std::optional<diagnosis::DiagnosisWithoutNetwork> without;  // without one
  {
    const ClearLine clear{tty};
    if (gyro)
      network = diagnosis::Diagnose(data, *gyro, o);
    else
      without = diagnosis::DiagnoseWithoutNetwork(data, o);
  }
  const nlohmann::json j = network ? diagnosis::DiagnosisJson(*network) : diagnosis::DiagnosisJson(*without);
  std::vector<std::string> report_files;
  if (report) {
    if (network)
      report_files = WriteReport(*report, *network, &network->extended_gyro, diagnosis::BiasTemperatureChannel(*gyro), j);
    else
      report_files = WriteReport(*report, *without, nullptr, without->polynomial_channel, j);
  }
  if (a.json) {
    fmt::print("{}\n", j.dump(2));
    return 0;
  }
  diagnosis::DiagnosisTextOptions text;
  text.data_name = a.data;
  text.gyro_name = a.gyro;
  fmt::print("{}", network ? diagnosis::DiagnosisText(*network, text) : diagnosis::DiagnosisText(*without, text));
  if (!a.report.empty()) fmt::print("\nreport in {}: {}\n", a.report, fmt::join(report_files, ", "));
  return 0;
}

namespace {

sim::Trace ImportColumnsOf(const ImportArgs& a) {
  if (a.files.size() != 1) throw InputError(fmt::format("import columns: expected one log file, got {}", a.files.size()));
  if (a.time.empty() || a.rate.empty() || a.temps.empty()) {
    throw InputError("import columns: --time, --temp and --rate are required (e.g. --time timestamp:us --temp "
                     "temperature --rate gyro_x:dps)");
  }
  sim::Trace trace = io::ImportColumnsAsWritten(a.files.front(), a.time, a.temps, a.rate, a.run, a.split_at_s);
  for (const auto& w : io::FahrenheitWarnings(trace)) fmt::print(stderr, "rlgtherm: warning: {}: {}\n", a.files.front(), w);
  return trace;
}

}  // namespace

int RunImport(const ImportArgs& a) {
  const bool columns = a.format == "columns";
  if (!columns && a.format != "tclab") {
    throw InputError(fmt::format("import: unknown format '{}'; known: tclab, columns", a.format));
  }
  if (!columns && (!a.time.empty() || !a.rate.empty() || !a.temps.empty() || !a.run.empty() || !a.split_at_s.empty())) {
    throw InputError("import tclab: --time, --temp, --rate, --run and --split-at are options of import columns");
  }
  sim::Trace trace;
  if (columns) {
    trace = ImportColumnsOf(a);
  } else {
    trace.comments.push_back("imported by rlgtherm import tclab; heater power = drive % x nominal gain (1e-2, 7.5e-3 W/%)");
    for (const auto& f : a.files) trace.runs.push_back(io::ImportTclab(f));
  }
  io::WriteFileAtomically(a.out, [&](std::ostream& out) { io::WriteTraceCsv(trace, out); });
  if (a.out != "-") {
    for (const auto& r : trace.runs)
      fmt::print("{}: {} samples, t = {:g} ... {:g} s (a power-on of its own)\n", r.id, r.size(), r.t_s.front(), r.t_s.back());
  }
  return 0;
}

Verb RegisterDiagnose(CLI::App& app) {
  auto a = std::make_shared<DiagnoseArgs>();
  CLI::App* cmd = app.add_subcommand("diagnose",
                                     "calibrate the gyro to data, name what it misses, extend it (or, "
                                     "without --gyro, what the best polynomial in temperature misses)");
  cmd->add_option("DATA", a->data, "tidy CSV ('-' = stdin); bias_dph optional (thermal-only data)")->required();
  cmd->add_option("--gyro", a->gyro,
                  "nominal gyro TOML; without it, the bias is searched alone against the "
                  "measured temperatures (a polynomial baseline, no thermal network)");
  cmd->add_option("--max-steps", a->max_steps, "extensions to accept at most")->capture_default_str();
  cmd->add_option("--lookahead", a->lookahead,
                  "thermal candidates tied in score compared one step ahead (1: the leader alone; "
                  "docs/diagnosis.md, The method)")
      ->capture_default_str();
  cmd->add_option("--fit-runs", a->fit_runs, "runs to fit on; the others are held out (default: all, cross-validated)")
      ->delimiter(',');
  cmd->add_flag("--per-run-gains", a->per_run_gains,
                "each run has its own gain for every data-driven source (runs from different boards)");
  cmd->add_flag("--power", a->power,
                "also the first thermal search's power: for each thermal and sensor candidate, the size it "
                "would be detected and named at with 90 % probability (docs/diagnosis.md, Power)");
  cmd->add_flag("--json", a->json, "the diagnosis report as JSON on stdout (keys: docs/data-format.md)");
  cmd->add_option("--report", a->report,
                  "directory for diagnosis.json, residuals.csv, extended-gyro.toml (with --gyro) and "
                  "fit_<channel>.png figures");
  return {cmd, [a] { return RunDiagnose(*a); }};
}

Verb RegisterImport(CLI::App& app) {
  auto a = std::make_shared<ImportArgs>();
  CLI::App* cmd = app.add_subcommand("import", "convert measured logs to the tidy CSV");
  cmd->add_option("FORMAT", a->format,
                  "log format: tclab (TCLab logs, one run each) or columns (any delimited log with a header "
                  "row: comma, tab or semicolon)")
      ->required();
  cmd->add_option("FILES", a->files, "log files (columns: one)")->required();
  cmd->add_option("-o,--output", a->out, "output CSV ('-' = stdout)");
  cmd->add_option(
      "--time", a->time,
      "columns: the time column and its unit, COL:s, COL:ms, COL:us or COL:ns; t_s counts from the first row");
  cmd->add_option("--temp", a->temps, "columns: temperature columns in °C, COL[,COL..], written as T1, T2, ..")
      ->delimiter(',');
  cmd->add_option("--rate", a->rate,
                  "columns: the rate column and its unit, COL:dph, COL:dps or COL:radps, written as bias_dph in °/h");
  cmd->add_option("--run", a->run, "columns: the run id (default: the file name without extension)");
  cmd->add_option("--split-at", a->split_at_s,
                  "columns: cut the log into runs ID-1, ID-2, .. at these times (s from the first row)")
      ->delimiter(',');
  return {cmd, [a] { return RunImport(*a); }};
}

}  // namespace rlg::cli
