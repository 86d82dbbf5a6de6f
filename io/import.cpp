#include "io/import.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <fstream>
#include <string_view>
#include <utility>

#include "io/csv.h"
#include "io/error_context.h"
#include "io/input_file.h"
#include "sim/errors.h"
#include "sim/limits.h"
#include "sim/trace_limits.h"

namespace rlg::io {

using sim::Run;
using sim::RunIdProblem;
using sim::Trace;

Run ImportTclab(const std::string& path, const TclabOptions& o) {
  std::ifstream in(path);
  if (!IsRegularFile(path) || !in) throw InputError(fmt::format("{}: cannot open TCLab log", path));
  Run run;
  run.id = std::filesystem::path(path).stem().string();
  run.source = path;
  if (const std::string why = RunIdProblem(run.id); !why.empty()) {
    throw InputError(fmt::format("{}: the file name gives the run id, but {}; rename the file", path, why));
  }
  const CsvReadOptions limits;  // what the tidy CSV it becomes can hold
  auto& T1 = run.AddColumn("T1");
  auto& T2 = run.AddColumn("T2");
  auto& P1 = run.AddColumn("P_heater1_W");
  auto& P2 = run.AddColumn("P_heater2_W");
  std::string line;
  int line_no = 0;
  double t_first = 0.0;
  while (std::getline(in, line)) {
    ++line_no;
    if (line_no == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 byte-order mark
    if (line.empty() || line == "\r") continue;
    double v[5];
    size_t start = 0;
    bool numeric = true;
    for (int f = 0; f < 5; ++f) {
      const size_t comma = line.find(',', start);
      if (comma == std::string::npos && f < 4) {
        throw InputError(fmt::format("{}:{}: expected at least 5 comma-separated fields (time, heater 1 %, heater 2 %, "
                                     "T1, T2)", path, line_no));
      }
      std::string field = line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      while (!field.empty() && (field.front() == ' ')) field.erase(field.begin());
      while (!field.empty() && (field.back() == ' ' || field.back() == '\r')) field.pop_back();
      const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), v[f]);
      if (ec != std::errc() || ptr != field.data() + field.size() || !std::isfinite(v[f])) {
        numeric = false;
        if (run.t_s.empty() && line_no == 1) break;  // the header line
        throw InputError(fmt::format("{}:{}: field {}: expected a finite number, found '{}'", path, line_no, f + 1, field));
      }
      start = comma + 1;
    }
    if (!numeric) continue;
    if (run.t_s.empty()) t_first = v[0];
    const double t = v[0] - t_first;
    if (!run.t_s.empty() && !(t > run.t_s.back())) {
      throw InputError(fmt::format("{}:{}: time must increase ({} after {})", path, line_no, v[0], run.t_s.back() + t_first));
    }
    if (v[1] < 0.0 || v[1] > 100.0 || v[2] < 0.0 || v[2] > 100.0) {
      throw InputError(fmt::format("{}:{}: heater drive must be 0...100 %", path, line_no));
    }
    if (const std::string why = sim::TimeProblem(t, limits); !why.empty()) {
      throw InputError(fmt::format("{}:{}: field 1: {}", path, line_no, why));
    }
    for (int f = 3; f < 5; ++f) {
      const std::string why = sim::RangeProblem(sim::RangeOf("T1", limits), v[f]);
      if (!why.empty()) throw InputError(fmt::format("{}:{}: field {}: {}", path, line_no, f + 1, why));
    }
    run.t_s.push_back(t);
    P1.push_back(v[1] * o.heater1_W_per_percent);
    P2.push_back(v[2] * o.heater2_W_per_percent);
    T1.push_back(v[3]);
    T2.push_back(v[4]);
  }
  if (run.t_s.size() < 2) throw InputError(fmt::format("{}: no data rows", path));
  return run;
}

}  // namespace rlg::io

namespace rlg::io {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string_view TrimView(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '"')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\r' || s.back() == '"')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> SplitOn(std::string_view line, char delimiter) {
  std::vector<std::string_view> out;
  size_t start = 0;
  while (true) {
    const size_t at = line.find(delimiter, start);
    out.push_back(TrimView(line.substr(start, at == std::string_view::npos ? std::string_view::npos : at - start)));
    if (at == std::string_view::npos) return out;
    start = at + 1;
  }
}

/// The number of fields of `line` at `delimiter`, counted before splitting it.
size_t FieldCount(std::string_view line, char delimiter) {
  return 1 + static_cast<size_t>(std::count(line.begin(), line.end(), delimiter));
}

/// The unit of `units` that the column's name ends in ("time_ms", "rate[dps]", "t (s)"), or "".
std::string UnitInName(const std::string& name, const std::vector<std::pair<std::string, double>>& units) {
  for (const auto& [unit, factor] : units) {
    for (const std::string& written : {"_" + unit, "-" + unit, "." + unit, " " + unit, "[" + unit + "]", "(" + unit + ")"}) {
      if (name.size() > written.size() && name.compare(name.size() - written.size(), written.size(), written) == 0) {
        return unit;
      }
    }
  }
  return "";
}

/// "NAME:UNIT" of `flag`; the unit has no default (`why`: what a wrong one would do).
LogColumn ParseColumn(const std::string& spec, const std::string& flag, const std::string& why,
                      const std::vector<std::pair<std::string, double>>& units) {
  LogColumn c;
  const size_t colon = spec.rfind(':');
  c.name = spec.substr(0, colon);
  c.unit = colon == std::string::npos ? "" : spec.substr(colon + 1);
  if (c.name.empty()) throw InputError(fmt::format("import columns: {} '{}': expected a column name", flag, spec));
  if (c.unit.empty()) {
    std::vector<std::string> names;
    for (const auto& u : units) names.push_back(c.name + ":" + u.first);
    const std::string guess = UnitInName(c.name, units);
    throw InputError(fmt::format("import columns: {} '{}': give the column's unit: {} (there is no default: {}){}", flag,
                                 spec, fmt::join(names, ", "), why,
                                 guess.empty() ? "" : fmt::format("; the name says {}: {} {}:{}", guess, flag, c.name, guess)));
  }
  for (const auto& [unit, factor] : units) {
    if (unit == c.unit) {
      c.factor = factor;
      return c;
    }
  }
  std::vector<std::string> names;
  for (const auto& u : units) names.push_back(u.first);
  throw InputError(fmt::format("import columns: {} '{}': unknown unit '{}' (expected {})", flag, spec, c.unit,
                               fmt::join(names, ", ")));
}

}  // namespace

LogColumn ParseTimeColumn(const std::string& spec) {
  return ParseColumn(spec, "--time", "milliseconds read as seconds make every time 1000 times too long",
                     {{"s", 1.0}, {"ms", 1e3}, {"us", 1e6}, {"ns", 1e9}});  // ticks per s
}

LogColumn ParseRateColumn(const std::string& spec) {
  return ParseColumn(spec, "--rate", "°/s read as °/h are 3600 times too small and look plausible",
                     {{"dph", 1.0}, {"dps", 3600.0}, {"radps", 3600.0 * 180.0 / kPi}});
}

bool ColumnsOptions::IsValid(std::string* error) const {
  auto fail = [&](const std::string& why) {
    if (error) *error = why;
    return false;
  };
  if (time.name.empty() || rate.name.empty()) return fail("a time and a rate column are needed (--time, --rate)");
  if (temperatures.empty()) return fail("at least one temperature column is needed (--temp)");
  for (const auto& t : temperatures)
    if (t.name.empty()) return fail("an empty temperature column name in --temp");
  for (size_t i = 0; i < split_at_s.size(); ++i) {
    if (!(split_at_s[i] > 0.0) || !std::isfinite(split_at_s[i]) || (i > 0 && !(split_at_s[i] > split_at_s[i - 1]))) {
      return fail("--split-at: expected times in s after the first row, increasing");
    }
  }
  return true;
}

namespace {

/// A log's header: the first line that is not empty, split on the delimiter that splits it
/// most (comma, tab or semicolon).
struct LogHeader {
  std::vector<std::string> names;
  char delimiter = ',';
  int lines = 0;  ///< lines read up to and with the header
  const char* DelimiterName() const { return delimiter == ',' ? "comma" : delimiter == '\t' ? "tab" : "semicolon"; }
};

LogHeader ReadLogHeader(std::istream& in, const std::string& path) {
  LogHeader h;
  std::string line;
  for (HeaderLine read; h.names.empty() && (read = ReadHeaderLine(in, line, ",\t;")) != HeaderLine::kEnd;) {
    ++h.lines;
    if (read == HeaderLine::kTooWide) {
      throw InputError(fmt::format("{}:{}: the header has more than the {} columns a data file may have (no gyro or "
                                   "chamber log is that wide; expected one header row, then one row per sample)",
                                   path, h.lines, sim::limits::kMaxColumns));
    }
    if (h.lines == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);  // UTF-8 byte-order mark
    if (TrimView(line).empty()) continue;
    size_t best = 0;
    for (const char d : {',', '\t', ';'}) {
      const size_t n = FieldCount(line, d);
      if (n > best) best = n, h.delimiter = d;
    }
    for (const auto f : SplitOn(line, h.delimiter)) h.names.emplace_back(f);
  }
  if (h.names.empty()) throw InputError(fmt::format("{}: empty file (expected a header row and data rows)", path));
  return h;
}

/// The header's column `c` names, by name or by its 1-based position; InputError naming `flag`
/// (--time, --rate, --temp) and the columns there are.
size_t ColumnIndex(const LogHeader& h, const LogColumn& c, const std::string& flag, const std::string& path) {
  const std::vector<std::string>& header = h.names;
  for (size_t i = 0; i < header.size(); ++i)
    if (header[i] == c.name) return i;
  size_t position = 0;
  const auto [ptr, ec] = std::from_chars(c.name.data(), c.name.data() + c.name.size(), position);
  if (ec == std::errc() && ptr == c.name.data() + c.name.size() && position >= 1 && position <= header.size()) {
    return position - 1;
  }
  if (header.size() == 1 && header[0].find(' ') != std::string::npos) {
    throw InputError(fmt::format("{}:{}: {}: no column '{}': the header is one field, '{}'; expected columns separated by "
                                 "commas, tabs or semicolons (spaces do not separate columns)",
                                 path, h.lines, flag, c.name, header[0]));
  }
  throw InputError(fmt::format("{}:{}: {}: no column '{}' in the header ({}-separated: {})", path, h.lines, flag, c.name,
                               h.DelimiterName(), ListForMessage(header, ", ")));
}

/// For a time out of range: the first unit smaller than the time column's that puts the row
/// (`raw_t`, the first row's `t_first`) within a day of the first, what the stamps most likely
/// are; empty when none.
std::string TimeUnitHint(double raw_t, double t_first, const LogColumn& time) {
  for (const auto& [unit, ticks] : {std::pair{"ms", 1e3}, std::pair{"us", 1e6}, std::pair{"ns", 1e9}}) {
    if (ticks <= time.factor) continue;
    const double seconds = (raw_t - t_first) / ticks;
    if (std::abs(seconds) < 86400.0 || std::string_view(unit) == "ns") {
      return fmt::format("; is the time column in {}? (--time {}:{} makes this row {:g} s)", unit, time.name, unit, seconds);
    }
  }
  return "";
}

/// InputError for an import without rows, a run of fewer than 2 samples, or a --split-at after
/// the last row (`next_split`: the first split not passed; `t_last`: the last row's time).
void CheckImported(const Trace& trace, const std::string& path, const ColumnsOptions& o, size_t next_split, double t_last) {
  if (trace.runs.empty()) throw InputError(fmt::format("{}: no data rows after the header", path));
  for (const auto& r : trace.runs) {
    if (r.size() < 2) {
      throw InputError(fmt::format("{}: {} sample{}: a run needs at least 2 (check --split-at)", r.Where(), r.size(),
                                   r.size() == 1 ? "" : "s"));
    }
  }
  if (next_split < o.split_at_s.size()) {
    throw InputError(fmt::format("{}: --split-at {} s is after the log's last row (t = {} s)", path,
                                 o.split_at_s[next_split], t_last));
  }
}

}  // namespace

Trace ImportColumns(const std::string& path, const ColumnsOptions& o) {
  if (std::string why; !o.IsValid(&why)) throw InputError("import columns: " + why);
  std::ifstream in(path, std::ios::binary);
  if (!IsRegularFile(path) || !in) throw InputError(fmt::format("{}: cannot open the log", path));
  const LogHeader log = ReadLogHeader(in, path);
  const std::vector<std::string>& header = log.names;
  const char delimiter = log.delimiter;
  const char* delimiter_name = log.DelimiterName();
  std::string line;
  int line_no = log.lines;
  auto index_of = [&](const LogColumn& c, const std::string& flag) { return ColumnIndex(log, c, flag, path); };
  const size_t time_col = index_of(o.time, "--time");
  const size_t rate_col = index_of(o.rate, "--rate");
  std::vector<size_t> temp_cols;
  for (const auto& t : o.temperatures) temp_cols.push_back(index_of(t, "--temp"));

  const std::string stem = o.run.empty() ? std::filesystem::path(path).stem().string() : o.run;
  if (const std::string why = RunIdProblem(stem); !why.empty()) {
    throw InputError(fmt::format("{}: the run id comes from {}, but {}", path, o.run.empty() ? "the file name" : "--run", why));
  }
  Trace trace;
  trace.source = path;
  auto new_run = [&](int first_line) {
    Run& r = trace.runs.emplace_back();
    r.id = o.split_at_s.empty() ? stem : fmt::format("{}-{}", stem, trace.runs.size());
    r.source = path;
    r.first_line = first_line;
    for (size_t k = 0; k < temp_cols.size(); ++k) r.AddColumn(fmt::format("T{}", k + 1));
    r.AddColumn("bias_dph");
    return &r;
  };
  const CsvReadOptions limits;  // what the tidy CSV it becomes can hold
  const auto temperature_range = sim::RangeOf("T1", limits);
  const auto bias_range = sim::RangeOf("bias_dph", limits);
  auto number = [&](std::string_view field, size_t col) {
    std::string text(field);
    if (delimiter != ',') std::replace(text.begin(), text.end(), ',', '.');  // a decimal comma
    double v = 0.0;
    const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
    if (text.empty() || ec != std::errc() || ptr != text.data() + text.size() || !std::isfinite(v)) {
      throw InputError(fmt::format("{}:{}: column {} ('{}'): expected a finite number, found '{}'", path, line_no, col + 1,
                                   header[col], field));
    }
    return v;
  };
  Run* run = nullptr;
  size_t next_split = 0;
  double t_first = 0.0, t_last = 0.0;
  bool first = true;
  while (std::getline(in, line)) {
    ++line_no;
    if (TrimView(line).empty()) continue;
    if (const size_t n = FieldCount(line, delimiter); n != header.size()) {
      throw InputError(fmt::format("{}:{}: expected {} {}-separated fields as in the header, found {}", path, line_no,
                                   header.size(), delimiter_name, n));
    }
    const auto fields = SplitOn(line, delimiter);
    const double raw_t = number(fields[time_col], time_col);
    if (first) t_first = raw_t;
    const double t = (raw_t - t_first) / o.time.factor;  // the difference first: µs stamps are ~1e14
    if (!first && !(t > t_last)) {
      throw InputError(fmt::format("{}:{}: column {} ('{}'): time must increase ({} after {})", path, line_no,
                                   time_col + 1, header[time_col], fields[time_col], t_last * o.time.factor + t_first));
    }
    if (const std::string why = sim::TimeProblem(t, limits); !why.empty()) {
      const std::string hint = TimeUnitHint(raw_t, t_first, o.time);
      throw InputError(fmt::format("{}:{}: column {} ('{}'): {}{}", path, line_no, time_col + 1, header[time_col], why, hint));
    }
    const size_t passed = next_split;
    while (next_split < o.split_at_s.size() && t >= o.split_at_s[next_split]) ++next_split;
    if (next_split > passed + 1) {
      throw InputError(fmt::format("{}:{}: --split-at {} s and {} s hold no row between them", path, line_no,
                                   o.split_at_s[passed], o.split_at_s[passed + 1]));
    }
    if (next_split > passed) run = nullptr;  // this row starts the next run
    if (run == nullptr) run = new_run(line_no);
    run->t_s.push_back(t);
    for (size_t k = 0; k < temp_cols.size(); ++k) {
      const double v = number(fields[temp_cols[k]], temp_cols[k]);
      if (const std::string why = sim::RangeProblem(temperature_range, v); !why.empty()) {
        throw InputError(fmt::format("{}:{}: column {} ('{}'): {}", path, line_no, temp_cols[k] + 1, header[temp_cols[k]], why));
      }
      run->columns[k].push_back(v);
    }
    const double rate = number(fields[rate_col], rate_col) * o.rate.factor;
    if (const std::string why = sim::RangeProblem(bias_range, rate); !why.empty()) {
      throw InputError(fmt::format("{}:{}: column {} ('{}'): {}", path, line_no, rate_col + 1, header[rate_col], why));
    }
    run->columns.back().push_back(rate);
    t_last = t;
    first = false;
  }
  CheckImported(trace, path, o, next_split, t_last);
  return trace;
}

Trace ImportColumnsAsWritten(const std::string& path, const std::string& time,
                             const std::vector<std::string>& temperatures, const std::string& rate, const std::string& run,
                             const std::vector<double>& split_at_s) {
  ColumnsOptions o;
  // Units without a default: a refusal names the log they were given for.
  o.time = WithContext("", path, [&] { return ParseTimeColumn(time); });
  o.rate = WithContext("", path, [&] { return ParseRateColumn(rate); });
  for (const auto& t : temperatures) o.temperatures.push_back({t, "C", 1.0});
  o.run = run;
  o.split_at_s = split_at_s;
  Trace trace = ImportColumns(path, o);
  std::vector<std::string> temps;
  for (size_t k = 0; k < o.temperatures.size(); ++k) temps.push_back(fmt::format("T{} = {}", k + 1, o.temperatures[k].name));
  trace.comments.push_back(fmt::format("imported by rlgtherm import columns from {}: t_s = {} ({}) from the first row, {}, "
                                       "bias_dph = {} ({} x {:g})",
                                       std::filesystem::path(path).filename().string(), o.time.name, o.time.unit,
                                       fmt::join(temps, ", "), o.rate.name, o.rate.unit, o.rate.factor));
  return trace;
}

std::vector<std::string> FahrenheitWarnings(const sim::Trace& trace) {
  std::vector<std::string> out;
  for (const auto& run : trace.runs) {
    for (size_t c = 0; c < run.names.size(); ++c) {
      if (!sim::IsTemperature(run.names[c]) || run.columns[c].empty()) continue;
      const auto [lo, hi] = std::minmax_element(run.columns[c].begin(), run.columns[c].end());
      const bool hot = *hi > kImplausibleAbove_C, warm = *lo > kImplausibleFloor_C;
      if (!hot && !warm) continue;
      out.push_back(fmt::format("run '{}': {} spans {:.1f} ... {:.1f} °C, {}: is the log in °F? That is {:.1f} ... "
                                "{:.1f} °C; convert it, (°F - 32) / 1.8",
                                run.id, run.names[c], *lo, *hi,
                                hot ? fmt::format("above {:g} °C", kImplausibleAbove_C)
                                    : fmt::format("never below {:g} °C", kImplausibleFloor_C),
                                (*lo - 32.0) / 1.8, (*hi - 32.0) / 1.8));
    }
  }
  return out;
}

}  // namespace rlg::io
