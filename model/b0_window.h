#pragma once
/// The power-on offset B0 of a run, as the paper's gyro computer measures it: "the average bias
/// of the former two minutes" after power-on,
///
///   B0 = mean of B(t_k) over t_first <= t_k < t_first + window_s      (°/h; window_s in s)
///
/// read causally: during the window B0 is the running mean of the samples so far, and the first
/// sample at or past its end freezes it. Eq. (2)'s compensator (compensation/compensator.h) and
/// the polynomial family's (model/linear_compensator.h) both keep their B0 in one of these, so
/// that streaming and batch compensation agree to the bit.

namespace rlg::model {

/// The paper's B0 window, s: every command's and function's default `b0_window_s`.
inline constexpr double kB0Window_s = 120.0;

class B0Window {
 public:
  explicit B0Window(double window_s = kB0Window_s) : window_s_(window_s) {}

  /// Forgets the run: the next sample is a power-on.
  void Reset() {
    started_ = frozen_ = false;
    sum_ = 0.0;
    count_ = 0;
    value_ = 0.0;
  }
  /// One sample of the run, in time order: true when it lies inside the window and joined the
  /// mean (count() then counts it), false once the window has passed (B0 frozen).
  bool Add(double t_s, double bias_dph) {
    if (!started_) {
      started_ = true;
      t_first_ = t_s;
    }
    if (frozen_) return false;
    if (t_s < t_first_ + window_s_) {
      sum_ += bias_dph;
      ++count_;
      value_ = sum_ / static_cast<double>(count_);
      return true;
    }
    frozen_ = true;
    return false;
  }

  double value() const { return value_; }  ///< B0 so far, °/h (0 before the first sample)
  bool frozen() const { return frozen_; }   ///< the window has passed
  long count() const { return count_; }     ///< samples in the mean
  double window_s() const { return window_s_; }

 private:
  double window_s_;
  bool started_ = false;
  bool frozen_ = false;
  double t_first_ = 0.0;
  double sum_ = 0.0;
  long count_ = 0;
  double value_ = 0.0;
};

}  // namespace rlg::model
