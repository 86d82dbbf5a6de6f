#include "sim/effects/gradient.h"

#include "sim/limits.h"

namespace rlg::sim {

GradientEffect::GradientEffect()
    : Effect("bias.gradient", EffectKind::kBias,
             {{"k_dph_per_C", "°/h/°C", false, -1.0, 1.0,
               "[est] bias follows spatial gradients (Wu & Gu, PLANS 2002; Honeywell US 8,781,778, docs/physics.md); the "
               "default gyro's largest, Langmuir flow along the anode leg, is 0.45 °/h/°C",
               -limits::kMaxBiasPerC, limits::kMaxBiasPerC, std::nullopt}}) {}

void GradientEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  const auto [a, b] = ResolvePair(gyro, target, false);
  gyro.bias.extra_gradients.push_back({a, b, p.at("k_dph_per_C")});
}

}  // namespace rlg::sim
