#pragma once
/// The tidy CSV of docs/data-format.md: reading with validation (file, line, column and what was
/// expected on any error), writing with fixed per-unit precision (so a seed gives the same
/// bytes), and whole-or-nothing file output.

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "sim/limits.h"
#include "sim/output_file.h"
#include "sim/trace.h"

namespace rlg::sim {

/// What the reader accepts. The limits are sim/limits.h's physical ones; a value beyond one is
/// refused with file, line, column and the limit.
struct CsvReadOptions {
  /// bias_dph is required unless the data is thermal-only (diagnose on a heater board).
  bool require_bias = true;
  /// Plausible temperature range for every T* column (docs/data-format.md).
  double min_temperature_C = limits::kMinTemperature_C;
  double max_temperature_C = limits::kMaxTemperature_C;
  /// |bias_dph| (°/h): beyond any laser gyro's measuring range.
  double max_abs_bias_dph = limits::kMaxAbsBias_dph;
  /// |t_s| (s since power-on): 32 years.
  double max_abs_time_s = limits::kMaxAbsTime_s;
  /// |P_<source>_W| (W).
  double max_abs_power_W = limits::kMaxAbsPower_W;
  /// Columns to keep although the tidy CSV does not name them (e.g. a user's own compensated bias,
  /// `rlgtherm allan --column my_comp_dph`); each must be in the header. Checked as bias columns.
  std::vector<std::string> keep_columns;
};

/// Why `id` cannot be a run id of the tidy CSV (empty when it can): it must be non-empty, hold no
/// comma, quote or control character (a line break would split the row), not start with '#'
/// (the line would read as a comment) and not start or end with a space (the reader trims them).
std::string RunIdProblem(const std::string& id);

/// The first value of `run` that ReadTraceCsv with `options` would refuse, as "column 'T1' =
/// 163.2 at t = 3600 s: <what the reader expects>"; empty when the whole run can be read back.
/// Writers of traces the user did not type (simulate) check with it before writing.
std::string FindUnreadableValue(const Run& run, const CsvReadOptions& options = {});

struct CsvReadResult {
  Trace trace;
  std::vector<std::string> warnings;  ///< e.g. the one "ignored extra columns" warning
};

/// One data row: run id, time and the kept columns in CsvRowReader::names() order.
struct CsvRow {
  std::string run;
  bool new_run = false;  ///< first row of its run
  double t_s = 0.0;
  std::vector<double> values;
};

/// Row-by-row reader of the tidy CSV, for streams (stdin) and files alike: the header is read
/// and checked on construction, every row is validated as it is read (see ReadTraceCsv).
class CsvRowReader {
 public:
  CsvRowReader(std::istream& in, std::string path, const CsvReadOptions& options = {});
  /// Kept data columns after run and t_s, in file order.
  const std::vector<std::string>& names() const { return names_; }
  const std::vector<std::string>& comments() const { return comments_; }
  const std::vector<std::string>& warnings() const { return warnings_; }
  /// Reads the next data row; false at the end of the input.
  bool Next(CsvRow& row);
  int line() const { return line_no_; }
  /// The source named in messages ("<stdin>" or a file path), as given.
  const std::string& path() const { return path_; }

  /// The physical limits a value column is checked against (CsvReadOptions), by column name.
  struct Range {
    double lo, hi;
    const char* quantity;  // "temperature", "bias", "power"; nullptr = no limit
    const char* unit;
  };
  /// The physical limits of a column named `name` (none for columns of no known kind).
  static Range RangeOf(const std::string& name, const CsvReadOptions& options);
  /// What is wrong with `v` in a column of range `r`; empty when nothing.
  static std::string RangeProblem(const Range& r, double v);
  static std::string TimeProblem(double t_s, const CsvReadOptions& options);

 private:
  [[noreturn]] void Fail(int column, const std::string& what) const;
  static constexpr int kRunColumn = -2, kTimeColumn = -3, kIgnored = -1;
  std::istream& in_;
  std::string path_;
  CsvReadOptions options_;
  int line_no_ = 0;
  std::vector<std::string> header_, names_, comments_, warnings_, seen_runs_;
  std::vector<int> keep_;  // header index -> value index, or one of the k* markers
  std::vector<Range> ranges_;  // value index -> its physical limits
  std::string current_run_;
  double last_t_ = 0.0;
};

/// Reads and validates a tidy CSV. Throws InputError on: missing or empty file, missing
/// required column, non-numeric / NaN / inf value, wrong field count, time not strictly
/// increasing inside a run, a run's rows not contiguous, a bad run id (RunIdProblem), a
/// temperature, bias, power or time beyond the limits of CsvReadOptions. A UTF-8 byte-order mark
/// at the start (spreadsheet exports write one) is skipped.
CsvReadResult ReadTraceCsv(const std::string& path, const CsvReadOptions& options = {});
CsvReadResult ReadTraceCsv(std::istream& in, const std::string& path, const CsvReadOptions& options = {});
/// The refusal of a file that ends after its header (`line`: the last line read), one text for
/// the batch and the streaming readers.
[[noreturn]] void ThrowNoDataRows(const std::string& path, int line);

/// The value `v` of column `name` as WriteTraceCsv writes it and ReadTraceCsv reads it back
/// (the fixed per-unit precision): what a report on a column that is also written should use,
/// so that reading the file reproduces the report to the bit.
double AsWritten(const std::string& name, double v);

/// Writes tidy CSV rows one at a time with the fixed per-unit precision (temperatures 4
/// decimals, bias 6): the one formatter behind WriteTraceCsv and streaming output.
class CsvRowWriter {
 public:
  /// Writes the comment lines and the header run,t_s,<names>.
  CsvRowWriter(std::ostream& out, std::vector<std::string> names, const std::vector<std::string>& comments = {});
  ~CsvRowWriter();
  void Write(const std::string& run, double t_s, const double* values);
  /// Hands buffered text to the stream and flushes it.
  void Flush();

 private:
  std::ostream& out_;
  std::vector<std::string> names_;
  std::vector<int> decimals_;
  std::string buf_;
  std::string last_run_;  // run id already checked
};

/// Writes a trace as tidy CSV, row by row (no second copy in memory). All runs must have the
/// same columns.
void WriteTraceCsv(const Trace& trace, std::ostream& out);
/// The same into a string (tests, small traces).
std::string FormatTraceCsv(const Trace& trace);

// WriteFileAtomically, for every output file, is in sim/output_file.h: a file is written as
// `.<name>.rlgtherm-partial-<pid>` beside it and renamed when whole; such a file found later is
// the unfinished output of a killed rlgtherm process (SIGKILL cannot be caught) and safe to delete.

}  // namespace rlg::sim
