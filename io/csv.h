#pragma once
/// The tidy CSV of docs/data-format.md: reading with validation (file, line, column and what was
/// expected on any error), writing with fixed per-unit precision (so a seed gives the same
/// bytes), and whole-or-nothing file output.

#include <functional>
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

#include "io/atomic_output.h"
#include "sim/trace.h"
#include "sim/trace_limits.h"

namespace rlg::io {

/// What the reader accepts: the limits of sim/trace_limits.h (a value beyond one is refused
/// with file, line, column and the limit), and whether a bias column is required.
struct CsvReadOptions : sim::TraceLimits {
  /// bias_dph is required unless the data is thermal-only (diagnose on a heater board).
  bool require_bias = true;
};

struct CsvReadResult {
  sim::Trace trace;
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

 private:
  [[noreturn]] void Fail(int column, const std::string& what) const;
  static constexpr int kRunColumn = -2, kTimeColumn = -3, kIgnored = -1;
  std::istream& in_;
  std::string path_;
  CsvReadOptions options_;
  int line_no_ = 0;
  std::vector<std::string> header_, names_, comments_, warnings_, seen_runs_;
  std::vector<int> keep_;  // header index -> value index, or one of the k* markers
  std::vector<std::string_view> fields_;  // the current line's fields, reused from row to row
  std::vector<sim::ValueRange> ranges_;  // value index -> its physical limits
  std::string current_run_;
  double last_t_ = 0.0;
};

/// How ReadHeaderLine ended: a whole line, no line left, or a line wider than allowed.
enum class HeaderLine { kRead, kEnd, kTooWide };
/// std::getline for a header: the next line of `in` into `line` (without its '\n'), unless it
/// has more than sim::limits::kMaxColumns fields at one of `delimiters`: then kTooWide as soon
/// as the field after the limit begins, with `line` holding the part read, so that a header of
/// millions of columns is refused after its first 65,536 in time and memory of those alone.
HeaderLine ReadHeaderLine(std::istream& in, std::string& line, std::string_view delimiters);

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
void WriteTraceCsv(const sim::Trace& trace, std::ostream& out);
/// The same into a string (tests, small traces).
std::string FormatTraceCsv(const sim::Trace& trace);

// WriteFileAtomically, for every output file, is in io/output_file.h: a file is written as
// `.<name>.rlgtherm-partial-<pid>` beside it and renamed when whole; such a file found later is
// the unfinished output of a killed rlgtherm process (SIGKILL cannot be caught) and safe to delete.

}  // namespace rlg::io
