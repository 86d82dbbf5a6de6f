#include "sim/effects/hysteresis.h"

#include <memory>

#include "sim/limits.h"

namespace rlg::sim {
namespace {

EffectParameter Coefficient(const std::string& name) {
  return {name, "°/h/°C", false, -0.5, 0.5,
          "[est] bias-temperature correlation changes with run time and direction (Acta Optica Sinica 29(4), "
          "2009, docs/physics.md); a coefficient beyond the default gyro's largest (Langmuir, 0.45 °/h/°C) needs a reason",
          -limits::kMaxBiasPerC, limits::kMaxBiasPerC, std::nullopt};
}

}  // namespace

HysteresisEffect::HysteresisEffect()
    : Effect("bias.hysteresis", EffectKind::kBias,
             {Coefficient("k_heating_dph_per_C"), Coefficient("k_cooling_dph_per_C")}) {}

void HysteresisEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  gyro.bias.hysteresis.push_back(
      {ResolveNode(gyro, target, false), p.at("k_heating_dph_per_C"), p.at("k_cooling_dph_per_C")});
}

}  // namespace rlg::sim
