#pragma once
/// bias.temperature_rate: a bias term proportional to a node's rate of temperature change,
///
///   B = k dT_n/dt
///
/// k in °/h per °C/min (k_dph_per_C_per_min), dT_n/dt in °C/min (the simulator's rate in
/// °C/s times 60). Target: a node, or a channel for the node its sensor sits on.

#include "sim/effect.h"

namespace rlg::sim {

class TemperatureRateEffect final : public Effect {
 public:
  TemperatureRateEffect();
  /// The term (°/h) at a node rate Tdot (°C/s): what BiasModel adds, and at k = 1 the
  /// regressor `diagnose` fits (diagnosis/catalog/).
  static double Bias_dph(double k_dph_per_C_per_min, double Tdot_C_per_s) {
    return k_dph_per_C_per_min * Tdot_C_per_s * 60.0;
  }
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
};

}  // namespace rlg::sim
