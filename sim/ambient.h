#pragma once
/// Scalar inputs over time: the ambient (chamber) temperature in °C, or a heat source's power
/// in W. A Profile is immutable; Value(t) is cheap. Breakpoints() lists the times where the
/// value or its slope is discontinuous, so the integrator can stop and restart there instead
/// of smoothing over a kink.

#include <utility>
#include <vector>

namespace rlg::sim {

class Profile {
 public:
  enum class Kind { kConstant, kRamp, kTable, kSteps, kSine };

  /// value(t) = v.
  static Profile Constant(double value);
  /// start before start_s, then start + rate (t - start_s) until it reaches end, then end.
  /// Precondition: rate != 0 and its sign points from start to end (std::invalid_argument).
  static Profile Ramp(double start, double rate_per_s, double start_s, double end);
  /// Piecewise linear through (t, v) points, held constant outside them.
  /// Precondition: at least one point, times strictly increasing.
  static Profile Table(std::vector<std::pair<double, double>> points);
  /// initial, then jumps to v_k at t_k (right-continuous). Precondition: times increasing.
  static Profile Steps(double initial, std::vector<std::pair<double, double>> steps);
  /// mean + amplitude sin(2 pi t / period + phase). Precondition: period > 0.
  static Profile Sine(double mean, double amplitude, double period_s, double phase_rad);

  double Value(double t_s) const;
  /// Value(t) for each of `times` (ascending) into out[0 .. times.size()), walking a table's or
  /// steps' points once instead of searching them for every sample.
  void ValuesAt(const std::vector<double>& times, double* out) const;
  /// Times of value or slope discontinuities, ascending.
  std::vector<double> Breakpoints() const;
  Kind kind() const { return kind_; }

 private:
  Profile(Kind kind, std::vector<double> params, std::vector<std::pair<double, double>> points)
      : kind_(kind), p_(std::move(params)), points_(std::move(points)) {}
  Kind kind_;
  std::vector<double> p_;
  std::vector<std::pair<double, double>> points_;
};

/// The fewest points of `points` (times increasing) whose piecewise-linear curve stays within
/// `tolerance` of every dropped point: greedy, each segment extended while all the points it
/// spans lie within tolerance of it. Keeps the first and last point. A measured input with
/// long straight stretches (a ramp, a dwell) then has breakpoints only at its corners.
std::vector<std::pair<double, double>> SimplifyPolyline(const std::vector<std::pair<double, double>>& points,
                                                        double tolerance);

}  // namespace rlg::sim
