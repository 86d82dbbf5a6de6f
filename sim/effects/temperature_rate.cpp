#include "sim/effects/temperature_rate.h"

#include "sim/limits.h"

namespace rlg::sim {

TemperatureRateEffect::TemperatureRateEffect()
    : Effect("bias.temperature_rate", EffectKind::kBias,
             {{"k_dph_per_C_per_min", "°/h per °C/min", false, -1.0, 1.0,
               "[est] dT/dt terms improve compensation (Sensors 20(2):377, 2020, docs/physics.md); beyond 1 °/h per "
               "°C/min a 1 °C/min ramp would move the bias by more than the paper's whole run-mean bias (0.63-1.42 "
               "°/h)",
               -limits::kMaxBiasPerRate, limits::kMaxBiasPerRate, std::nullopt}}) {}

void TemperatureRateEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  gyro.bias.rate_terms.push_back({ResolveNode(gyro, target, false), p.at("k_dph_per_C_per_min")});
}

}  // namespace rlg::sim
