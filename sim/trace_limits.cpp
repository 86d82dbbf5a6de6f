#include "sim/trace_limits.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fmt/format.h>

namespace rlg::sim {

bool IsTemperature(const std::string& name) {
  return name.size() >= 2 && name[0] == 'T' && (std::isdigit(static_cast<unsigned char>(name[1])) || name[1] == '_');
}

bool IsKnownColumn(const std::string& name) {
  if (name == "bias_dph" || IsTemperature(name)) return true;
  return name.size() > 4 && name.rfind("P_", 0) == 0 && name.substr(name.size() - 2) == "_W";
}

ValueRange RangeOf(const std::string& name, const TraceLimits& o) {
  if (IsTemperature(name)) return {o.min_temperature_C, o.max_temperature_C, "temperature", "°C"};
  if (name == "bias_dph") return {-o.max_abs_bias_dph, o.max_abs_bias_dph, "bias", "°/h"};
  if (IsKnownColumn(name)) return {-o.max_abs_power_W, o.max_abs_power_W, "power", "W"};  // P_<source>_W
  // A column kept by name is a bias column of the user's (allan/compensate --column).
  if (std::find(o.keep_columns.begin(), o.keep_columns.end(), name) != o.keep_columns.end()) {
    return {-o.max_abs_bias_dph, o.max_abs_bias_dph, "bias", "°/h"};
  }
  return {-INFINITY, INFINITY, nullptr, ""};
}

std::string RangeProblem(const ValueRange& r, double v) {
  if (v >= r.lo && v <= r.hi) return "";
  if (r.lo == -r.hi) {
    return fmt::format("{} {:g} {} is beyond ±{:g} {} (is the unit {}?)", r.quantity, v, r.unit,
                       r.hi, r.unit, r.unit);
  }
  std::string hint;
  // A temperature between the range's ends plus 273.15 K reads like kelvin.
  if (std::string_view(r.unit) == "°C" && v - 273.15 >= r.lo && v - 273.15 <= r.hi) {
    hint = fmt::format(" (kelvin? T columns are in °C: {:g} K is {:g} °C)", v, v - 273.15);
  }
  return fmt::format("{} {} {} is outside the plausible range {}...{} {}{}", r.quantity, v, r.unit, r.lo, r.hi, r.unit,
                     hint);
}

std::string TimeProblem(double t, const TraceLimits& o) {
  if (std::abs(t) <= o.max_abs_time_s) return "";
  return fmt::format("time {:g} s is beyond ±{:g} s (expected seconds since power-on)", t, o.max_abs_time_s);
}

std::string RunIdProblem(const std::string& id) {
  if (id.empty()) return "empty run id";
  for (const char c : id) {
    if (c == ',' || c == '"' || static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
      return fmt::format("run id '{}' holds a comma, quote or control character", id);
    }
  }
  if (id.front() == '#') return fmt::format("run id '{}' starts with '#' (the line would read as a comment)", id);
  if (id.front() == ' ' || id.back() == ' ') return fmt::format("run id '{}' starts or ends with a space", id);
  return "";
}

std::string FindUnreadableValue(const Run& run, const TraceLimits& options) {
  if (const std::string why = RunIdProblem(run.id); !why.empty()) return why;
  for (size_t k = 0; k < run.size(); ++k) {
    if (const std::string why = TimeProblem(run.t_s[k], options); !why.empty()) {
      return fmt::format("t = {} s: {}", run.t_s[k], why);
    }
    if (k > 0 && !(run.t_s[k] > run.t_s[k - 1])) return fmt::format("t = {} s: time does not increase", run.t_s[k]);
  }
  for (size_t c = 0; c < run.names.size(); ++c) {
    const ValueRange range = RangeOf(run.names[c], options);
    for (size_t k = 0; k < run.size(); ++k) {
      const double v = run.columns[c][k];
      if (v >= range.lo && v <= range.hi) continue;  // the common case, without building a message
      std::string why = std::isfinite(v) ? RangeProblem(range, v) : "not a finite number";
      if (!why.empty()) return fmt::format("column '{}' = {} at t = {} s: {}", run.names[c], v, run.t_s[k], why);
    }
  }
  return "";
}

}  // namespace rlg::sim
