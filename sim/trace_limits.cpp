#include "sim/trace_limits.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fmt/format.h>
#if defined(__SSE2__) && !defined(RLG_NO_SIMD)
#include <emmintrin.h>
#endif

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

namespace {

/// lo <= v[k] <= hi for every k < n (false for a NaN): four values at a time with SSE2, which
/// every x86-64 has.
bool AllInRange(const double* v, size_t n, double lo, double hi) {
  size_t k = 0;
  bool inside = true;
#if defined(__SSE2__) && !defined(RLG_NO_SIMD)
  const __m128d lo2 = _mm_set1_pd(lo), hi2 = _mm_set1_pd(hi);
  __m128d all = _mm_castsi128_pd(_mm_set1_epi64x(-1)), all2 = all;
  for (; k + 4 <= n; k += 4) {
    const __m128d x = _mm_loadu_pd(v + k), y = _mm_loadu_pd(v + k + 2);
    all = _mm_and_pd(all, _mm_and_pd(_mm_cmpge_pd(x, lo2), _mm_cmple_pd(x, hi2)));
    all2 = _mm_and_pd(all2, _mm_and_pd(_mm_cmpge_pd(y, lo2), _mm_cmple_pd(y, hi2)));
  }
  inside = _mm_movemask_pd(_mm_and_pd(all, all2)) == 3;
#endif
  for (; k < n; ++k) inside = inside && v[k] >= lo && v[k] <= hi;
  return inside;
}

/// t[k] > t[k - 1] for every 0 < k < n (false for a NaN).
bool Increasing(const double* t, size_t n) {
  size_t k = 1;
  bool increasing = true;
#if defined(__SSE2__) && !defined(RLG_NO_SIMD)
  __m128d all = _mm_castsi128_pd(_mm_set1_epi64x(-1));
  for (; k + 2 <= n; k += 2) all = _mm_and_pd(all, _mm_cmpgt_pd(_mm_loadu_pd(t + k), _mm_loadu_pd(t + k - 1)));
  increasing = _mm_movemask_pd(all) == 3;
#endif
  for (; k < n; ++k) increasing = increasing && t[k] > t[k - 1];
  return increasing;
}

}  // namespace

std::string FindUnreadableValue(const Run& run, const TraceLimits& options) {
  if (const std::string why = RunIdProblem(run.id); !why.empty()) return why;
  // The common case first: every time within its limit and increasing, every value inside its
  // column's range (a NaN is inside none), checked a vector at a time without a message per
  // sample (~3 % of a population gyro's CPU). Only a run with a value outside is searched for it.
  const size_t n = run.size();
  const double* const t = run.t_s.data();
  bool inside = AllInRange(t, n, -options.max_abs_time_s, options.max_abs_time_s) && Increasing(t, n);
  for (size_t c = 0; inside && c < run.names.size(); ++c) {
    const ValueRange range = RangeOf(run.names[c], options);
    inside = AllInRange(run.columns[c].data(), n, range.lo, range.hi);
  }
  if (inside) return "";
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
