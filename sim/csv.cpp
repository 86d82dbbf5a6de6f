#include "sim/csv.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <sstream>
#include <unistd.h>

#include "sim/errors.h"

namespace rlg::sim {

int Run::Find(const std::string& name) const {
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<int>(i);
  return -1;
}

const std::vector<double>& Run::Column(const std::string& name) const {
  const int i = Find(name);
  if (i < 0) throw InputError(fmt::format("run '{}' has no column '{}'", id, name));
  return columns[i];
}

std::vector<double>& Run::AddColumn(const std::string& name) {
  names.push_back(name);
  columns.emplace_back();
  columns.back().reserve(t_s.capacity());
  return columns.back();
}

const Run& Trace::FindRun(const std::string& id) const {
  std::string ids;
  for (const auto& r : runs) {
    if (r.id == id) return r;
    ids += (ids.empty() ? "" : ", ") + r.id;
  }
  throw InputError(fmt::format("no run '{}' in the data (runs: {})", id, ids));
}

namespace {

bool IsTemperature(const std::string& name) {
  return name.size() >= 2 && name[0] == 'T' && (std::isdigit(static_cast<unsigned char>(name[1])) || name[1] == '_');
}

bool IsKnownColumn(const std::string& name) {
  if (name == "bias_dph" || IsTemperature(name)) return true;
  return name.size() > 4 && name.rfind("P_", 0) == 0 && name.substr(name.size() - 2) == "_W";
}

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> Split(std::string_view line) {
  std::vector<std::string_view> out;
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    out.push_back(Trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

}  // namespace

CsvReadResult ReadTraceCsv(const std::string& path, const CsvReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!std::filesystem::is_regular_file(path) || !in) {
    throw InputError(fmt::format("{}: cannot open data file (expected a tidy CSV, SPEC section 2)", path));
  }
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();

  CsvReadResult result;
  Trace& trace = result.trace;
  std::vector<std::string> header;
  std::vector<int> keep;  // header index -> column index in Run (-1 = ignored, -2 = run, -3 = t_s)
  std::vector<std::string> kept_names;
  std::vector<std::string> seen_runs;
  size_t pos = 0;
  int line_no = 0;
  auto fail = [&](int col, const std::string& what) -> void {
    if (col >= 0 && col < static_cast<int>(header.size())) {
      throw InputError(fmt::format("{}:{}: column {} ('{}'): {}", path, line_no, col + 1, header[col], what));
    }
    throw InputError(fmt::format("{}:{}: {}", path, line_no, what));
  };

  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    const std::string_view line = Trim(std::string_view(text).substr(pos, end - pos));
    pos = end + 1;
    ++line_no;
    if (line.empty()) continue;
    if (line.front() == '#') {
      if (header.empty()) trace.comments.emplace_back(Trim(line.substr(1)));
      continue;
    }
    const auto fields = Split(line);
    if (header.empty()) {
      for (const auto& f : fields) header.emplace_back(f);
      auto has = [&](const char* name) { return std::find(header.begin(), header.end(), name) != header.end(); };
      std::vector<std::string> required = {"run", "t_s", "T1"};
      if (options.require_bias) required.push_back("bias_dph");
      for (const auto& r : required) {
        if (!has(r.c_str())) {
          fail(-1, fmt::format("missing required column '{}' in the header (expected at least: {})", r,
                               fmt::join(required, ",")));
        }
      }
      std::vector<std::string> ignored;
      for (size_t i = 0; i < header.size(); ++i) {
        if (std::count(header.begin(), header.end(), header[i]) > 1) fail(static_cast<int>(i), "column name repeated");
        if (header[i] == "run") {
          keep.push_back(-2);
        } else if (header[i] == "t_s") {
          keep.push_back(-3);
        } else if (IsKnownColumn(header[i])) {
          keep.push_back(static_cast<int>(kept_names.size()));
          kept_names.push_back(header[i]);
        } else {
          keep.push_back(-1);
          ignored.push_back(header[i]);
        }
      }
      if (!ignored.empty()) {
        result.warnings.push_back(fmt::format("{}: ignoring extra columns: {}", path, fmt::join(ignored, ", ")));
      }
      continue;
    }
    if (fields.size() != header.size()) {
      fail(-1, fmt::format("expected {} comma-separated fields as in the header, found {}", header.size(), fields.size()));
    }
    std::string_view run_id;
    for (size_t i = 0; i < fields.size(); ++i)
      if (keep[i] == -2) run_id = fields[i];
    if (run_id.empty()) fail(-1, "empty run id");
    if (trace.runs.empty() || trace.runs.back().id != run_id) {
      if (std::find(seen_runs.begin(), seen_runs.end(), run_id) != seen_runs.end()) {
        fail(-1, fmt::format("rows of run '{}' are not contiguous (rows must be grouped by run)", run_id));
      }
      seen_runs.emplace_back(run_id);
      Run run;
      run.id = std::string(run_id);
      for (const auto& n : kept_names) run.AddColumn(n);
      trace.runs.push_back(std::move(run));
    }
    Run& run = trace.runs.back();
    for (size_t i = 0; i < fields.size(); ++i) {
      if (keep[i] == -2 || keep[i] == -1) continue;
      const std::string_view f = fields[i];
      double v = 0.0;
      const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
      if (f.empty() || ec != std::errc() || ptr != f.data() + f.size()) {
        fail(static_cast<int>(i), fmt::format("expected a number, found '{}'", f));
      }
      if (!std::isfinite(v)) fail(static_cast<int>(i), fmt::format("expected a finite number, found '{}'", f));
      if (keep[i] == -3) {
        if (!run.t_s.empty() && !(v > run.t_s.back())) {
          fail(static_cast<int>(i), fmt::format("time must increase strictly inside run '{}' ({} after {})", run.id, v,
                                                run.t_s.back()));
        }
        run.t_s.push_back(v);
        continue;
      }
      if (IsTemperature(header[i]) && (v < options.min_temperature_C || v > options.max_temperature_C)) {
        fail(static_cast<int>(i), fmt::format("temperature {} °C is outside the plausible range {}...{} °C", v,
                                              options.min_temperature_C, options.max_temperature_C));
      }
      run.columns[keep[i]].push_back(v);
    }
  }
  if (header.empty()) throw InputError(fmt::format("{}: empty file (expected a header line and data rows)", path));
  if (trace.runs.empty()) throw InputError(fmt::format("{}:{}: no data rows after the header", path, line_no));
  return result;
}

namespace {

int Decimals(const std::string& name) {
  if (IsTemperature(name)) return 4;  // 0.1 mK: finer than any sensor resolution
  if (name == "bias_dph") return 6;   // 1e-6 °/h: far below the 1 s noise
  return 6;
}

void AppendNumber(fmt::memory_buffer& out, double v, int decimals) {
  static const double kScale[] = {1, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6};
  double r = std::round(v * kScale[decimals]) / kScale[decimals];
  if (r == 0.0) r = 0.0;  // no "-0.0000"
  fmt::format_to(std::back_inserter(out), "{:.{}f}", r, decimals);
}

}  // namespace

void WriteTraceCsv(const Trace& trace, std::ostream& out) {
  fmt::memory_buffer buf;
  auto flush = [&] {
    out.write(buf.data(), static_cast<std::streamsize>(buf.size()));
    buf.clear();
  };
  for (const auto& c : trace.comments) fmt::format_to(std::back_inserter(buf), "# {}\n", c);
  if (!trace.runs.empty()) {
    const auto& names = trace.runs.front().names;
    fmt::format_to(std::back_inserter(buf), "run,t_s");
    for (const auto& n : names) fmt::format_to(std::back_inserter(buf), ",{}", n);
    buf.push_back('\n');
    std::vector<int> decimals;
    for (const auto& n : names) decimals.push_back(Decimals(n));
    for (const auto& run : trace.runs) {
      if (run.names != names) throw std::logic_error("WriteTraceCsv: runs with different columns");
      for (size_t k = 0; k < run.size(); ++k) {
        fmt::format_to(std::back_inserter(buf), "{},{}", run.id, run.t_s[k]);
        for (size_t c = 0; c < names.size(); ++c) {
          buf.push_back(',');
          AppendNumber(buf, run.columns[c][k], decimals[c]);
        }
        buf.push_back('\n');
        if (buf.size() > (1 << 16)) flush();
      }
    }
  }
  flush();
}

std::string FormatTraceCsv(const Trace& trace) {
  std::ostringstream out;
  WriteTraceCsv(trace, out);
  return out.str();
}

void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (path == "-") {
    write(std::cout);
    std::cout.flush();
    return;
  }
  const std::string tmp = fmt::format("{}.tmp-{}", path, ::getpid());
  try {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw InputError(fmt::format("{}: cannot write output file", path));
    write(out);
    out.close();
    if (!out) throw InputError(fmt::format("{}: writing failed (disk full?)", path));
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    throw InputError(fmt::format("{}: cannot move the finished file into place", path));
  }
}

}  // namespace rlg::sim
