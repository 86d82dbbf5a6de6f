#pragma once
/// The causal operators that the extra terms of the polynomial models (model/poly_model.h) are
/// built from. Each is advanced one sample at a time from power-on, as a gyro computer runs it,
/// and sees nothing of later samples. Units: T in °C, t in s.
///
///   RateFilter     dT/dt in °C/min: the backward difference d_k = 60 (T_k - T_{k-1}) / (t_k - t_{k-1})
///                  through a first-order low-pass of time constant tau_r:
///                    r_k = r_{k-1} + (1 - exp(-(t_k - t_{k-1}) / tau_r)) (d_k - r_{k-1}),  r_0 = 0
///                  (no history at power-on: no rate).
///   PlayOperator   the play (backlash) operator of width w:
///                    p_k = clamp(p_{k-1}, T_k - w/2, T_k + w/2),  p_0 = T_0
///                  so T - p is +w/2 on a heating branch, -w/2 on a cooling branch and moves
///                  one for one with T across a reversal: a loop w wide in °C.
///   FirstOrderLag  T_L' = (T - T_L) / tau, T_L(t_0) = T_0, advanced exactly for T linear between
///                  samples (first-order hold), with a = exp(-dt / tau):
///                    T_L,k = a T_L,k-1 + (1 - a) T_{k-1} + (T_k - T_{k-1}) phi,
///                    phi = 1 - tau (1 - a) / dt  (0 for dt << tau, 1 for dt >> tau).
///
/// A sample whose time does not advance (dt <= 0: only from a caller that skips the data's
/// checks) leaves the rate and the lag as they were.

namespace rlg::model {

class RateFilter {
 public:
  explicit RateFilter(double tau_s) : tau_s_(tau_s) {}
  void Reset() { started_ = false; }
  /// The filtered rate (°C/min) after sample (t_s, T).
  double Next(double t_s, double T);
  double tau_s() const { return tau_s_; }

 private:
  double tau_s_;
  bool started_ = false;
  double t_ = 0.0, T_ = 0.0, rate_ = 0.0;
  double dt_ = 0.0, gain_ = 0.0;  ///< the last time step and its 1 - exp(-dt / tau_r)
};

class PlayOperator {
 public:
  explicit PlayOperator(double width_C) : half_(0.5 * width_C) {}
  void Reset() { started_ = false; }
  /// The operator's output p_k after sample T_k (°C).
  double Next(double T);

 private:
  double half_;
  bool started_ = false;
  double p_ = 0.0;
};

class FirstOrderLag {
 public:
  explicit FirstOrderLag(double tau_s) : tau_s_(tau_s) {}
  void Reset() { started_ = false; }
  /// T_L after sample (t_s, T) (°C).
  double Next(double t_s, double T);

 private:
  double tau_s_;
  bool started_ = false;
  double t_ = 0.0, T_ = 0.0, lag_ = 0.0;
  double dt_ = 0.0, one_minus_a_ = 0.0, phi_ = 0.0;  ///< the last time step and its factors
};

}  // namespace rlg::model
