#pragma once
/// Converters from measured logs to the tidy CSV's Trace (docs/data-format.md).

#include <string>
#include <vector>

#include "sim/trace.h"

namespace rlg::io {

struct TclabOptions {
  /// Nominal heater powers per percent of drive (data/tclab/SOURCE.md); `diagnose`
  /// calibrates the gains, so these only set the starting point.
  double heater1_W_per_percent = 0.01;
  double heater2_W_per_percent = 0.0075;
};

/// One TCLab log (columns: time s, heater 1 %, heater 2 %, T1 °C, T2 °C, anything else
/// ignored; with or without a header line) as a run named after the file: columns T1, T2,
/// P_heater1_W, P_heater2_W, time from the first sample. InputError naming file and line.
sim::Run ImportTclab(const std::string& path, const TclabOptions& options = {});

/// A column of a delimited log: its header name (or 1-based position), the unit its values are
/// in and `factor`: for the rate, what turns a value into °/h (×); for the time, the ticks per
/// second (÷, so that 505630 µs is 0.50563 s exactly as written).
struct LogColumn {
  std::string name;
  std::string unit;
  double factor = 1.0;
};

/// What `rlgtherm import columns` reads from any delimited log with one header row.
struct ColumnsOptions {
  LogColumn time;                       ///< units s, ms, us, ns (no default)
  std::vector<LogColumn> temperatures;  ///< °C, written as T1, T2, ... in this order
  LogColumn rate;                       ///< units dph (°/h), dps (°/s), radps (rad/s); written as bias_dph
  std::string run;                     ///< run id; empty: the file's stem
  /// Cut the log into runs at these times (s from the first row, increasing): runs ID-1, ID-2,
  /// ...; each run's t_s keeps counting from the log's first row.
  std::vector<double> split_at_s;
  /// False with a reason: no temperature, an empty name, split times not increasing or not > 0.
  bool IsValid(std::string* error) const;
};

/// Parses "NAME:UNIT" for the time (s, ms, us, ns) and for the rate (dph, dps, radps). Neither
/// unit has a default: a time in ms read as s is 1000 times too long, a rate in °/s read as °/h
/// 3600 times too small and plausible. InputError naming the flag and the units it takes (and
/// the unit the name ends in, "time_ms").
LogColumn ParseTimeColumn(const std::string& spec);
LogColumn ParseRateColumn(const std::string& spec);

/// Reads a delimited log: the delimiter (comma, tab or semicolon) is the one the header row
/// splits on; with tab or semicolon, a decimal comma in a number is read as a point. Time from
/// the first row, converted to s; every row's named fields must be finite numbers, the time
/// strictly increasing and every value within the tidy CSV's limits. InputError naming file,
/// line and column otherwise. Other columns are ignored.
sim::Trace ImportColumns(const std::string& path, const ColumnsOptions& options);

/// `rlgtherm import columns LOG --time T --temp A,B.. --rate R [--run ID] [--split-at S,..]` as
/// written: the time and rate columns' "NAME:UNIT" parsed (a refusal names the log), the log read
/// (ImportColumns), and a comment saying what each column of the tidy CSV came from. The CLI's
/// command and the Python module's import_columns, so that both write the same bytes.
sim::Trace ImportColumnsAsWritten(const std::string& path, const std::string& time,
                                  const std::vector<std::string>& temperatures, const std::string& rate,
                                  const std::string& run, const std::vector<double>& split_at_s);

/// Warnings for temperature columns of `trace` that look like °F read as °C (the log has no unit
/// to check, and °F passes the tidy CSV's -80 ... 150 °C): a column that reaches above
/// kImplausibleAbove_C (a chamber's +60 °C is 140 °F), or one that never falls below
/// kImplausibleFloor_C over a run (a room's 20 °C is 68 °F). One per column and run, naming the
/// column, the run, its range and what it would be in °C were it °F; empty when none.
inline constexpr double kImplausibleAbove_C = 100.0;
inline constexpr double kImplausibleFloor_C = 50.0;
std::vector<std::string> FahrenheitWarnings(const sim::Trace& trace);

}  // namespace rlg::io
