#pragma once
/// What values a Trace may hold: the physical limits of sim/limits.h applied by column kind
/// (T* temperatures in °C, bias_dph in °/h, P_<source>_W in W, t_s in s since power-on) and
/// the rules for run ids. The tidy CSV's reader (io/csv.h) refuses what breaks them, naming
/// file, line and column; the simulator and the Python module check what they make with
/// FindUnreadableValue, so that nothing written can fail to be read back.

#include <string>
#include <vector>

#include "sim/limits.h"
#include "sim/trace.h"

namespace rlg::sim {

struct TraceLimits {
  /// Plausible temperature range for every T* column (°C).
  double min_temperature_C = limits::kMinTemperature_C;
  double max_temperature_C = limits::kMaxTemperature_C;
  /// |bias_dph| (°/h): beyond any laser gyro's measuring range.
  double max_abs_bias_dph = limits::kMaxAbsBias_dph;
  /// |t_s| (s since power-on): 32 years.
  double max_abs_time_s = limits::kMaxAbsTime_s;
  /// |P_<source>_W| (W).
  double max_abs_power_W = limits::kMaxAbsPower_W;
  /// Columns of no known kind that are kept (e.g. a user's own compensated bias, `rlgtherm
  /// allan --column my_comp_dph`): checked as bias columns.
  std::vector<std::string> keep_columns;
};

/// T1, T2, ..., T_amb: a temperature column (°C).
bool IsTemperature(const std::string& name);
/// bias_dph, a temperature or a power P_<source>_W.
bool IsKnownColumn(const std::string& name);

/// The limits a value column is checked against, by column name.
struct ValueRange {
  double lo, hi;
  const char* quantity;  ///< "temperature", "bias", "power"; nullptr = no limit
  const char* unit;
};
/// The limits of a column named `name` (none for columns of no known kind that are not kept).
ValueRange RangeOf(const std::string& name, const TraceLimits& limits);
/// What is wrong with `v` in a column of range `r` (with a hint where a unit looks mistaken,
/// e.g. kelvin in a °C column); empty when nothing.
std::string RangeProblem(const ValueRange& r, double v);
/// What is wrong with a time of `t_s` seconds since power-on; empty when nothing.
std::string TimeProblem(double t_s, const TraceLimits& limits);

/// Why `id` cannot be a run id of the tidy CSV (empty when it can): it must be non-empty, hold no
/// comma, quote or control character (a line break would split the row), not start with '#'
/// (the line would read as a comment) and not start or end with a space (the reader trims them).
std::string RunIdProblem(const std::string& id);

/// The first value of `run` that the tidy CSV's reader with `limits` would refuse, as "column
/// 'T1' = 163.2 at t = 3600 s: <what the reader expects>"; empty when the whole run can be read
/// back. Writers of traces the user did not type (simulate) check with it before writing.
std::string FindUnreadableValue(const Run& run, const TraceLimits& limits = {});

}  // namespace rlg::sim
