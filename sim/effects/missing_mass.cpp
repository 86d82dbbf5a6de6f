#include "sim/effects/missing_mass.h"

#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::sim {

MissingMassEffect::MissingMassEffect()
    : Effect("thermal.missing_mass", EffectKind::kThermal,
             {{"heat_capacity_J_per_K", "J/K", true, 1.0, 1000.0,
               "[est] a few grams of metal or glass (a mirror substrate, a bracket: ~1 J/K) to more than the block "
               "itself (0.3-0.5 kg of Zerodur: 250-410 J/K, docs/physics.md)",
               limits::kMinCapacity, limits::kMaxCapacity, std::nullopt},
              ConductanceParameter()}) {}

void MissingMassEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  auto& net = gyro.network;
  const auto [a, b] = ResolvePair(gyro, target, false);
  const double c = p.at("heat_capacity_J_per_K"), g = p.at("conductance_W_per_K");
  if (!(c > 0.0) || !(g > 0.0)) {
    throw InputError("thermal.missing_mass needs heat_capacity_J_per_K > 0 and conductance_W_per_K > 0");
  }
  const int m = static_cast<int>(net.nodes.size());
  net.nodes.push_back({net.nodes[a].name + "_" + net.nodes[b].name + "_mass", c});
  net.links.push_back({a, m, g});
  net.links.push_back({m, b, g});
}

}  // namespace rlg::sim
