#include "sim/ambient.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <fmt/format.h>
#include <stdexcept>

namespace rlg::sim {
namespace {

void CheckIncreasing(const std::vector<std::pair<double, double>>& pts, const char* what) {
  for (size_t i = 1; i < pts.size(); ++i) {
    if (!(pts[i].first > pts[i - 1].first)) {
      throw std::invalid_argument(fmt::format("{}: times must be strictly increasing, but entry {} (t = {:g} s) "
                                              "does not come after entry {} (t = {:g} s)",
                                              what, i + 1, pts[i].first, i, pts[i - 1].first));
    }
  }
  for (const auto& [t, v] : pts) {
    if (!std::isfinite(t) || !std::isfinite(v)) throw std::invalid_argument(std::string(what) + ": non-finite entry");
  }
}

}  // namespace

Profile Profile::Constant(double value) {
  if (!std::isfinite(value)) throw std::invalid_argument("constant: value must be finite");
  return Profile(Kind::kConstant, {value}, {});
}

Profile Profile::Ramp(double start, double rate_per_s, double start_s, double end) {
  if (!(rate_per_s != 0.0) || !std::isfinite(rate_per_s)) throw std::invalid_argument("ramp: rate must be finite and non-zero");
  if ((end - start) * rate_per_s < 0.0) {
    throw std::invalid_argument("ramp: rate has the wrong sign to go from start to end");
  }
  return Profile(Kind::kRamp, {start, rate_per_s, start_s, end}, {});
}

Profile Profile::Table(std::vector<std::pair<double, double>> points) {
  if (points.empty()) throw std::invalid_argument("table: needs at least one (t, value) point");
  CheckIncreasing(points, "table");
  return Profile(Kind::kTable, {}, std::move(points));
}

Profile Profile::Steps(double initial, std::vector<std::pair<double, double>> steps) {
  CheckIncreasing(steps, "steps");
  return Profile(Kind::kSteps, {initial}, std::move(steps));
}

Profile Profile::Sine(double mean, double amplitude, double period_s, double phase_rad) {
  if (!(period_s > 0.0)) throw std::invalid_argument("sine: period must be positive");
  return Profile(Kind::kSine, {mean, amplitude, period_s, phase_rad}, {});
}

double Profile::Value(double t) const {
  switch (kind_) {
    case Kind::kConstant:
      return p_[0];
    case Kind::kRamp: {
      const double start = p_[0], rate = p_[1], t0 = p_[2], end = p_[3];
      if (t <= t0) return start;
      const double v = start + rate * (t - t0);
      return rate > 0 ? std::min(v, end) : std::max(v, end);
    }
    case Kind::kTable: {
      if (t <= points_.front().first) return points_.front().second;
      if (t >= points_.back().first) return points_.back().second;
      const auto it = std::upper_bound(points_.begin(), points_.end(), t,
                                       [](double x, const std::pair<double, double>& p) { return x < p.first; });
      const auto& [t1, v1] = *it;
      const auto& [t0, v0] = *(it - 1);
      return v0 + (v1 - v0) * (t - t0) / (t1 - t0);
    }
    case Kind::kSteps: {
      double v = p_[0];
      for (const auto& [ts, vs] : points_) {
        if (t < ts) break;
        v = vs;
      }
      return v;
    }
    case Kind::kSine:
      return p_[0] + p_[1] * std::sin(2.0 * M_PI * t / p_[2] + p_[3]);
  }
  return 0.0;  // unreachable
}

void Profile::ValuesAt(const std::vector<double>& times, double* out) const {
  if (kind_ == Kind::kConstant) {  // a fill, not a call per sample (1.6 % of a population gyro)
    std::fill(out, out + times.size(), p_[0]);
    return;
  }
  if (kind_ != Kind::kTable && kind_ != Kind::kSteps) {
    for (size_t k = 0; k < times.size(); ++k) out[k] = Value(times[k]);
    return;
  }
  const size_t n = times.size();
  if (kind_ == Kind::kSteps) {
    // next = index of the first point with time > t, as Value's upper_bound / loop finds it.
    size_t next = 0;
    for (size_t k = 0; k < n; ++k) {
      while (next < points_.size() && points_[next].first <= times[k]) ++next;
      out[k] = next == 0 ? p_[0] : points_[next - 1].second;
    }
    return;
  }
  // Table: the first value up to the first point, then segment by segment (times sorted, so a
  // segment's samples are consecutive: a loop with one division each, which vectorises), then
  // the last value. Each sample gets Value's expression for its segment.
  size_t k = 0;
  for (; k < n && times[k] <= points_.front().first; ++k) out[k] = points_.front().second;
  for (size_t next = 1; next < points_.size(); ++next) {
    const auto& [t1, v1] = points_[next];
    const auto& [t0, v0] = points_[next - 1];
    const double rise = v1 - v0, run = t1 - t0;
    size_t end = k;
    while (end < n && times[end] < t1) ++end;
    for (; k < end; ++k) out[k] = v0 + rise * (times[k] - t0) / run;
  }
  for (; k < n; ++k) out[k] = points_.back().second;
}

std::vector<double> Profile::Breakpoints() const {
  std::vector<double> out;
  switch (kind_) {
    case Kind::kRamp:
      out = {p_[2], p_[2] + (p_[3] - p_[0]) / p_[1]};
      break;
    case Kind::kTable:
    case Kind::kSteps:
      for (const auto& pt : points_) out.push_back(pt.first);
      break;
    default:
      break;
  }
  return out;
}

std::vector<std::pair<double, double>> SimplifyPolyline(const std::vector<std::pair<double, double>>& points,
                                                        double tolerance) {
  if (points.size() <= 2) return points;
  // Does the chord from points[i] to points[j] pass within tolerance of every point between?
  // The definition, point by point: O(j - i).
  auto fits = [&](size_t i, size_t j) {
    const auto [t0, v0] = points[i];
    const double slope = (points[j].second - v0) / (points[j].first - t0);
    for (size_t k = i + 1; k < j; ++k)
      if (std::abs(v0 + slope * (points[k].first - t0) - points[k].second) > tolerance) return false;
    return true;
  };
  // The same answer in O(1) a point: the chord passes within tolerance of point k when its
  // slope lies in [(v_k - v0 - tol) / dt_k, (v_k - v0 + tol) / dt_k], so of every point so far
  // when it lies in the intersection, kept as the greatest lower and least upper bound. Bounds
  // moved inwards by delta_k decide "fits" for sure, moved outwards "does not"; delta_k, 1e-12
  // of the magnitudes, is a thousand times the rounding of the point-by-point test, so only a
  // slope within it of a bound (a chord through a point at exactly the tolerance) or a point
  // that is not finite or not later than points[i] is left to the definition. Without the sure
  // answers, a segment of L points cost O(L²): a day's constant ambient at 1 s took 6 s.
  std::vector<std::pair<double, double>> out = {points.front()};
  size_t i = 0;
  while (i + 1 < points.size()) {
    const double t0 = points[i].first, v0 = points[i].second;  // not a structured binding: the lambda below captures them
    constexpr double kInf = std::numeric_limits<double>::infinity();
    double lo_sure = -kInf, hi_sure = kInf, lo_maybe = -kInf, hi_maybe = kInf;
    bool decidable = true;  // every point so far finite and later than points[i]
    size_t j = i + 1;
    auto include = [&](size_t k) {
      const auto [t, v] = points[k];
      const double dt = t - t0;
      if (!(dt > 0.0) || !std::isfinite(dt) || !std::isfinite(v)) {
        decidable = false;
        return;
      }
      const double delta = 1e-12 * (std::abs(v0) + std::abs(v) + tolerance);
      lo_sure = std::max(lo_sure, (v - v0 - tolerance + delta) / dt);
      hi_sure = std::min(hi_sure, (v - v0 + tolerance - delta) / dt);
      lo_maybe = std::max(lo_maybe, (v - v0 - tolerance - delta) / dt);
      hi_maybe = std::min(hi_maybe, (v - v0 + tolerance + delta) / dt);
    };
    while (j + 1 < points.size()) {
      include(j);
      const double slope = (points[j + 1].second - v0) / (points[j + 1].first - t0);
      bool ok;
      if (decidable && slope >= lo_sure && slope <= hi_sure) {
        ok = true;
      } else if (decidable && (slope < lo_maybe || slope > hi_maybe)) {
        ok = false;
      } else {
        ok = fits(i, j + 1);
      }
      if (!ok) break;
      ++j;
    }
    out.push_back(points[j]);
    i = j;
  }
  return out;
}

}  // namespace rlg::sim
