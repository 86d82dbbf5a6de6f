#pragma once
/// bias.gradient: a bias term proportional to the temperature difference of two nodes that
/// the nominal bias model omits,
///
///   B = k (T_a - T_b)
///
/// k in °/h/°C (k_dph_per_C), T in °C. Target: a pair "a-b" (channels name their nodes).

#include "sim/effect.h"

namespace rlg::sim {

class GradientEffect final : public Effect {
 public:
  GradientEffect();
  /// The term (°/h): what BiasModel adds.
  static double Bias_dph(double k_dph_per_C, double T_a_C, double T_b_C) { return k_dph_per_C * (T_a_C - T_b_C); }
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
};

}  // namespace rlg::sim
