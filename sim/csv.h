#pragma once
/// The tidy CSV of SPEC section 2: reading with validation (file, line, column and what was
/// expected on any error), writing with fixed per-unit precision (so a seed gives the same
/// bytes), and whole-or-nothing file output.

#include <functional>
#include <iosfwd>
#include <string>
#include <vector>

#include "sim/trace.h"

namespace rlg::sim {

struct CsvReadOptions {
  /// bias_dph is required unless the data is thermal-only (diagnose on a heater board).
  bool require_bias = true;
  /// Plausible temperature range for every T* column (SPEC section 2).
  double min_temperature_C = -80.0;
  double max_temperature_C = 150.0;
};

struct CsvReadResult {
  Trace trace;
  std::vector<std::string> warnings;  ///< e.g. the one "ignored extra columns" warning
};

/// Reads and validates a tidy CSV. Throws InputError on: missing or empty file, missing
/// required column, non-numeric / NaN / inf value, wrong field count, time not strictly
/// increasing inside a run, a run's rows not contiguous, temperature out of range.
CsvReadResult ReadTraceCsv(const std::string& path, const CsvReadOptions& options = {});

/// Writes a trace as tidy CSV, row by row (no second copy in memory). All runs must have the
/// same columns.
void WriteTraceCsv(const Trace& trace, std::ostream& out);
/// The same into a string (tests, small traces).
std::string FormatTraceCsv(const Trace& trace);

/// Calls write(stream) for `path` and keeps the result whole or not at all: it goes to a
/// temporary file renamed into place only when write returns without throwing. "-" = stdout.
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

}  // namespace rlg::sim
