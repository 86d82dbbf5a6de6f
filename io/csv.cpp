#include "io/csv.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <iostream>
#include <sstream>
#include <unordered_map>
#include <unistd.h>

#include "io/error_context.h"
#include "io/input_file.h"
#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::io {

using sim::IsTemperature;
using sim::Run;
using sim::RunIdProblem;
using sim::Trace;

namespace {

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r')) s.remove_suffix(1);
  return s;
}

constexpr std::string_view kUtf8Bom = "\xEF\xBB\xBF";

}  // namespace

namespace {

/// The comma-separated fields of `line`, trimmed, into `out` (reused from row to row).
void Split(std::string_view line, std::vector<std::string_view>& out) {
  out.clear();
  size_t start = 0;
  while (true) {
    const size_t comma = line.find(',', start);
    out.push_back(Trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
}

/// The number of comma-separated fields of `line`, counted before splitting it: a line of a
/// million commas is refused without a million fields in memory.
size_t FieldCount(std::string_view line) { return 1 + static_cast<size_t>(std::count(line.begin(), line.end(), ',')); }

/// Why a header may lack the required columns: it is one field holding another separator.
std::string SeparatorHint(const std::vector<std::string>& header) {
  if (header.size() != 1) return "";
  for (const auto& [sep, name] : {std::pair{';', "semicolons"}, std::pair{'\t', "tabs"}, std::pair{'|', "bars"}}) {
    const auto n = std::count(header[0].begin(), header[0].end(), sep);
    if (n > 0) {
      return fmt::format("; the header has no comma but {} {}: the tidy CSV is comma-separated with '.' as the decimal "
                         "point (docs/data-format.md); `rlgtherm import columns` reads other delimiters",
                         n, name);
    }
  }
  return "";
}

/// Why a row may have more fields than the header: decimal commas ("20,5") split numbers.
std::string DecimalCommaHint(std::string_view line, size_t expected, size_t found) {
  if (found <= expected) return "";
  for (size_t i = 1; i + 1 < line.size(); ++i) {
    const auto digit = [](char c) { return c >= '0' && c <= '9'; };
    if (line[i] == ',' && digit(line[i - 1]) && digit(line[i + 1])) {
      return " (decimal commas? the tidy CSV uses '.' as the decimal point and ',' between fields)";
    }
  }
  return "";
}

}  // namespace

HeaderLine ReadHeaderLine(std::istream& in, std::string& line, std::string_view delimiters) {
  line.clear();
  const std::istream::sentry ok(in, /*noskipws=*/true);
  if (!ok) return HeaderLine::kEnd;
  std::vector<size_t> count(delimiters.size(), 0);
  std::streambuf* buf = in.rdbuf();
  for (int c = buf->sbumpc();; c = buf->sbumpc()) {
    if (c == std::char_traits<char>::eof()) {
      in.setstate(line.empty() ? std::ios::eofbit | std::ios::failbit : std::ios::eofbit);
      return line.empty() ? HeaderLine::kEnd : HeaderLine::kRead;
    }
    if (c == '\n') return HeaderLine::kRead;
    line.push_back(static_cast<char>(c));
    for (size_t d = 0; d < delimiters.size(); ++d) {
      // n delimiters make n + 1 fields.
      if (c == delimiters[d] && ++count[d] >= static_cast<size_t>(sim::limits::kMaxColumns)) return HeaderLine::kTooWide;
    }
  }
}

CsvRowReader::CsvRowReader(std::istream& in, std::string path, const CsvReadOptions& options)
    : in_(in), path_(std::move(path)), options_(options) {
  std::string text;
  for (HeaderLine read; (read = ReadHeaderLine(in_, text, ",")) != HeaderLine::kEnd;) {
    ++line_no_;
    std::string_view line = Trim(text);
    if (line_no_ == 1 && line.substr(0, kUtf8Bom.size()) == kUtf8Bom) line = Trim(line.substr(kUtf8Bom.size()));
    if (line.empty()) continue;
    if (line.front() == '#') {
      if (read == HeaderLine::kTooWide) {  // a comment may hold any number of commas
        std::string rest;
        std::getline(in_, rest);
        text += rest;
        line = Trim(std::string_view(text).substr(text.find('#')));
      }
      comments_.emplace_back(Trim(line.substr(1)));
      continue;
    }
    if (read == HeaderLine::kTooWide) {
      Fail(-1, fmt::format("the header has more than the {} columns a data file may have (no gyro or chamber log is "
                           "that wide; expected the tidy CSV's header run,t_s,T1,...,bias_dph, docs/data-format.md)",
                           sim::limits::kMaxColumns));
    }
    Split(line, fields_);
    header_.assign(fields_.begin(), fields_.end());
    break;
  }
  if (header_.empty()) throw InputError(fmt::format("{}: empty file (expected a header line and data rows)", path_));
  // Each name's first column, in one pass: time linear in the columns (a count of each name
  // against all the others took seconds at 40,000 columns).
  std::unordered_map<std::string_view, size_t> column_of;
  column_of.reserve(header_.size());
  for (size_t i = 0; i < header_.size(); ++i) column_of.emplace(header_[i], i);
  auto has = [&](const std::string& name) { return column_of.count(name) > 0; };
  std::vector<std::string> required = {"run", "t_s", "T1"};
  if (options_.require_bias) required.push_back("bias_dph");
  for (const auto& r : required) {
    if (!has(r)) {
      Fail(-1, fmt::format("missing required column '{}' in the header (expected at least: {}){}", r,
                           fmt::join(required, ","), SeparatorHint(header_)));
    }
  }
  const auto& kept = options_.keep_columns;
  auto has_kept = [&](const std::string& name) { return std::find(kept.begin(), kept.end(), name) != kept.end(); };
  for (const auto& k : kept) {
    if (!has(k)) Fail(-1, fmt::format("no column '{}' (the columns are: {})", k, ListForMessage(header_, ",")));
  }
  std::vector<std::string> ignored;
  for (size_t i = 0; i < header_.size(); ++i) {
    if (const size_t first = column_of.at(header_[i]); first != i) {
      Fail(static_cast<int>(i), fmt::format("column name repeated (column {} has it too)", first + 1));
    }
    if (header_[i] == "run") {
      keep_.push_back(kRunColumn);
    } else if (header_[i] == "t_s") {
      keep_.push_back(kTimeColumn);
    } else if (sim::IsKnownColumn(header_[i]) || has_kept(header_[i])) {
      keep_.push_back(static_cast<int>(names_.size()));
      names_.push_back(header_[i]);
      ranges_.push_back(sim::RangeOf(header_[i], options_));
    } else {
      keep_.push_back(kIgnored);
      ignored.push_back(header_[i]);
    }
  }
  if (!ignored.empty()) warnings_.push_back(fmt::format("{}: ignoring extra columns: {}", path_, ListForMessage(ignored, ", ")));
}

void CsvRowReader::Fail(int col, const std::string& what) const {
  if (col >= 0 && col < static_cast<int>(header_.size())) {
    throw InputError(fmt::format("{}:{}: column {} ('{}'): {}", path_, line_no_, col + 1, header_[col], what));
  }
  throw InputError(fmt::format("{}:{}: {}", path_, line_no_, what));
}

bool CsvRowReader::Next(CsvRow& row) {
  std::string text;
  while (std::getline(in_, text)) {
    ++line_no_;
    const std::string_view line = Trim(text);
    if (line.empty() || line.front() == '#') continue;
    if (const size_t n = FieldCount(line); n != header_.size()) {
      Fail(-1, fmt::format("expected {} comma-separated fields as in the header, found {}{}", header_.size(), n,
                           DecimalCommaHint(line, header_.size(), n)));
    }
    Split(line, fields_);
    const auto& fields = fields_;
    row.values.resize(names_.size());
    bool new_run = false;
    for (size_t i = 0; i < fields.size(); ++i) {
      if (keep_[i] != kRunColumn) continue;
      if (fields[i].empty()) Fail(static_cast<int>(i), "empty run id");
      new_run = fields[i] != current_run_;
      if (new_run) {
        if (const std::string why = RunIdProblem(std::string(fields[i])); !why.empty()) Fail(static_cast<int>(i), why);
      }
      if (new_run) {
        if (std::find(seen_runs_.begin(), seen_runs_.end(), fields[i]) != seen_runs_.end()) {
          Fail(-1, fmt::format("rows of run '{}' are not contiguous (rows must be grouped by run)", fields[i]));
        }
        current_run_ = std::string(fields[i]);
        seen_runs_.push_back(current_run_);
      }
    }
    row.run = current_run_;
    row.new_run = new_run;
    for (size_t i = 0; i < fields.size(); ++i) {
      if (keep_[i] == kRunColumn || keep_[i] == kIgnored) continue;
      const std::string_view f = fields[i];
      double v = 0.0;
      const auto [ptr, ec] = std::from_chars(f.data(), f.data() + f.size(), v);
      if (f.empty() || ec != std::errc() || ptr != f.data() + f.size()) {
        Fail(static_cast<int>(i), fmt::format("expected a number, found '{}'", f));
      }
      if (!std::isfinite(v)) Fail(static_cast<int>(i), fmt::format("expected a finite number, found '{}'", f));
      if (keep_[i] == kTimeColumn) {
        if (const std::string why = sim::TimeProblem(v, options_); !why.empty()) Fail(static_cast<int>(i), why);
        if (!new_run && !(v > last_t_)) {
          Fail(static_cast<int>(i), fmt::format("time must increase strictly inside run '{}' ({} after {})", current_run_,
                                                v, last_t_));
        }
        row.t_s = last_t_ = v;
        continue;
      }
      const sim::ValueRange& range = ranges_[keep_[i]];
      if (!(v >= range.lo && v <= range.hi)) Fail(static_cast<int>(i), sim::RangeProblem(range, v));
      row.values[keep_[i]] = v;
    }
    return true;
  }
  return false;
}

CsvReadResult ReadTraceCsv(const std::string& path, const CsvReadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!IsRegularFile(path) || !in) {
    throw InputError(fmt::format("{}: cannot open data file (expected a tidy CSV: run,t_s,T1,...,bias_dph; see docs/data-format.md)", path));
  }
  return ReadTraceCsv(in, path, options);
}

CsvReadResult ReadTraceCsv(std::istream& in, const std::string& path, const CsvReadOptions& options) {
  CsvRowReader reader(in, path, options);
  CsvReadResult result;
  result.trace.source = path;
  result.trace.comments = reader.comments();
  result.warnings = reader.warnings();
  CsvRow row;
  while (reader.Next(row)) {
    if (row.new_run) {
      Run run;
      run.id = row.run;
      run.source = path;
      run.first_line = reader.line();
      for (const auto& n : reader.names()) run.AddColumn(n);
      result.trace.runs.push_back(std::move(run));
    }
    Run& run = result.trace.runs.back();
    run.t_s.push_back(row.t_s);
    for (size_t c = 0; c < row.values.size(); ++c) run.columns[c].push_back(row.values[c]);
  }
  if (result.trace.runs.empty()) ThrowNoDataRows(path, reader.line());
  return result;
}

void ThrowNoDataRows(const std::string& path, int line) {
  throw InputError(fmt::format("{}:{}: no data rows after the header", path, line));
}

namespace {

int Decimals(const std::string& name) {
  if (IsTemperature(name)) return 4;  // 0.1 mK: finer than any sensor resolution
  if (name == "bias_dph") return 6;   // 1e-6 °/h: far below the 1 s noise
  return 6;
}

// v rounded to `decimals`: the double nearest to the decimal text written (k / 10^d, correctly
// rounded, is what strtod returns for that text), so formatting it writes that text and
// reading the text back gives it again.
double Rounded(double v, int decimals) {
  static const double kScale[] = {1, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6};
  // Beyond 2^52 a scaled double has no fraction left to round (and v * scale could overflow).
  const double scaled = v * kScale[decimals];
  double r = std::abs(scaled) < 0x1p52 ? std::round(scaled) / kScale[decimals] : v;
  if (r == 0.0) r = 0.0;  // no "-0.0000"
  return r;
}

void AppendNumber(fmt::memory_buffer& out, double v, int decimals) {
  fmt::format_to(std::back_inserter(out), "{:.{}f}", Rounded(v, decimals), decimals);
}

}  // namespace

double AsWritten(const std::string& name, double v) { return Rounded(v, Decimals(name)); }

CsvRowWriter::CsvRowWriter(std::ostream& out, std::vector<std::string> names, const std::vector<std::string>& comments)
    : out_(out), names_(std::move(names)) {
  for (std::string c : comments) {
    std::replace_if(c.begin(), c.end(), [](char ch) { return ch == '\n' || ch == '\r'; }, ' ');  // one line each
    buf_ += "# " + c + "\n";
  }
  buf_ += "run,t_s";
  for (const auto& n : names_) {
    buf_ += "," + n;
    decimals_.push_back(Decimals(n));
  }
  buf_ += "\n";
}

CsvRowWriter::~CsvRowWriter() {
  out_.write(buf_.data(), static_cast<std::streamsize>(buf_.size()));  // no flush: destructors must not throw
}

void CsvRowWriter::Write(const std::string& run, double t_s, const double* values) {
  // Every caller validated its runs (reader, scenario loader, import, simulate's limits): a value
  // the reader would refuse here is a bug, and an inf or NaN is never written.
  if (run != last_run_) {
    if (const std::string why = RunIdProblem(run); !why.empty()) throw std::logic_error("CsvRowWriter: " + why);
    last_run_ = run;
  }
  fmt::memory_buffer row;
  fmt::format_to(std::back_inserter(row), "{},{}", run, t_s);
  for (size_t c = 0; c < names_.size(); ++c) {
    if (!std::isfinite(values[c])) {
      throw NumericalError(fmt::format("run '{}' at t = {} s: column '{}' is {}, not a finite number; not written", run,
                                       t_s, names_[c], values[c]));
    }
    row.push_back(',');
    AppendNumber(row, values[c], decimals_[c]);
  }
  row.push_back('\n');
  buf_.append(row.data(), row.size());
  if (buf_.size() > (1 << 16)) {
    out_.write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
    buf_.clear();
  }
}

void CsvRowWriter::Flush() {
  out_.write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
  buf_.clear();
  out_.flush();
}

void WriteTraceCsv(const Trace& trace, std::ostream& out) {
  const std::vector<std::string> names = trace.runs.empty() ? std::vector<std::string>{} : trace.runs.front().names;
  CsvRowWriter writer(out, names, trace.comments);
  if (trace.runs.empty()) return;
  std::vector<double> values(names.size());
  for (const auto& run : trace.runs) {
    if (run.names != names) throw std::logic_error("WriteTraceCsv: runs with different columns");
    for (size_t k = 0; k < run.size(); ++k) {
      for (size_t c = 0; c < names.size(); ++c) values[c] = run.columns[c][k];
      writer.Write(run.id, run.t_s[k], values.data());
    }
  }
  writer.Flush();
}

std::string FormatTraceCsv(const Trace& trace) {
  std::ostringstream out;
  WriteTraceCsv(trace, out);
  return out.str();
}

}  // namespace rlg::io
