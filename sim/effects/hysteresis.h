#pragma once
/// bias.hysteresis: a different temperature coefficient while a node heats and while it cools,
///
///   B(t) = sum over steps since power-on of  k_heating dT_n  (dT_n >= 0)  or  k_cooling dT_n  (dT_n < 0)
///
/// k in °/h/°C (k_heating_dph_per_C, k_cooling_dph_per_C), T in °C. Target: a node or a
/// channel. Only k_heating - k_cooling can be told from a linear term of the baseline (the
/// sum of all steps is the node's change since power-on), so `diagnose` fits and reports
/// k_heating_minus_cooling_dph_per_C and applies it as k_heating with k_cooling = 0.

#include "sim/effect.h"

namespace rlg::sim {

class HysteresisEffect final : public Effect {
 public:
  HysteresisEffect();
  /// Advances one node's loop to temperature T_C (°C): adds k_heating (T_C - last_T_C) for a
  /// rise or k_cooling (T_C - last_T_C) for a fall to `accumulated_dph`, sets last_T_C = T_C
  /// and returns the term (°/h). BiasModel calls it every sample; `diagnose`'s regressor, the
  /// heating increments since power-on, is it with k_heating = 1, k_cooling = 0.
  static double Bias_dph(double k_heating_dph_per_C, double k_cooling_dph_per_C, double T_C, double& last_T_C,
                         double& accumulated_dph) {
    const double step = T_C - last_T_C;
    accumulated_dph += (step >= 0.0 ? k_heating_dph_per_C : k_cooling_dph_per_C) * step;
    last_T_C = T_C;
    return accumulated_dph;
  }
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
};

}  // namespace rlg::sim
