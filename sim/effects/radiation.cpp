#include "sim/effects/radiation.h"

#include "sim/limits.h"

namespace rlg::sim {

RadiationEffect::RadiationEffect()
    : Effect("thermal.radiation", EffectKind::kThermal,
             {{"emissivity_area_m2", "m²", true, 1e-6, 0.2,
               "[est] emissivity 0.03 (polished metal) to 0.9 (glass, paint) times 1 cm² to a case's ~0.2 m² (a 0.4 "
               "kg Zerodur block has ~0.04 m²)",
               0.0, limits::kMaxEmissivityArea, std::nullopt}}) {}

void RadiationEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  const auto [a, b] = ResolvePair(gyro, target, true);
  gyro.network.radiation.push_back({a, b, p.at("emissivity_area_m2")});
}

}  // namespace rlg::sim
