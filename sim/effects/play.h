#pragma once
/// bias.play: a temperature coefficient acting through a play (backlash) operator of width w,
///
///   B(t) = k (p(t) - T_ref),   p_0 = T_n(0),   p_k = clamp(p_{k-1}, T_n,k - w/2, T_n,k + w/2)
///
/// k in °/h/°C (k_dph_per_C), w in °C (width_C), T_ref in °C (reference_C, held), T_n the
/// target node's temperature at each sample. p follows T_n with a dead band: on a heating branch
/// p = T_n - w/2, on a cooling branch p = T_n + w/2, and across a reversal p holds still until
/// T_n has moved by w. The two branches of a cycle therefore sit k w apart in bias at the same
/// temperature (a loop of amplitude k w / 2 about k (T_n - T_ref)), however slowly the node
/// moves: a rate-independent hysteresis, unlike bias.hysteresis, which accumulates k dT and
/// leaves a branch offset that grows with the excursion. This is the elementary operator of
/// Prandtl–Ishlinskii hysteresis models (docs/physics.md); the power-on state p_0 = T_n(0) is
/// the centred one, as the polynomial models' hysteresis term starts (model/causal_operators.h,
/// PlayOperator: the same recursion, so T - p is that term's regressor).
///
/// `diagnose` does not try it (diagnosis/catalog/ gives it no regressor): its width is a shape parameter the linear
/// bias search cannot fit, and bias.hysteresis stands for direction dependence there.

#include "sim/effect.h"

namespace rlg::sim {

class PlayEffect final : public Effect {
 public:
  PlayEffect();
  /// The play operator's next output (°C) after a sample at T_C: `p_C` (the previous output,
  /// T at power-on for the first sample) clamped to [T_C - w/2, T_C + w/2].
  static double NextPlay(double width_C, double T_C, double p_C) {
    const double half = 0.5 * width_C;
    return p_C < T_C - half ? T_C - half : (p_C > T_C + half ? T_C + half : p_C);
  }
  /// Advances `p_C` to the sample at T_C and returns the term (°/h). BiasModel calls it every
  /// sample.
  static double Bias_dph(double k_dph_per_C, double width_C, double reference_C, double T_C, double& p_C) {
    p_C = NextPlay(width_C, T_C, p_C);
    return k_dph_per_C * (p_C - reference_C);
  }
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
};

}  // namespace rlg::sim
