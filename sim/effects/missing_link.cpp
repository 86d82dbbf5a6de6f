#include "sim/effects/missing_link.h"

namespace rlg::sim {

MissingLinkEffect::MissingLinkEffect()
    : Effect("thermal.missing_link", EffectKind::kThermal, {ConductanceParameter()}) {}

void MissingLinkEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  const auto [a, b] = ResolvePair(gyro, target, true);
  gyro.network.links.push_back({a, b, p.at("conductance_W_per_K")});
}

}  // namespace rlg::sim
