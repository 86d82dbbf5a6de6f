#include "sim/effects/missing_link.h"

namespace rlg::sim {
namespace {

/// Whether the first link between the pair's ends (either way round) conducts.
bool HasLink(const GyroConfig& g, const std::string& pair) {
  const auto dash = pair.find('-');
  const int a = g.network.FindNode(pair.substr(0, dash)), b = g.network.FindNode(pair.substr(dash + 1));
  for (const auto& l : g.network.links)
    if ((l.a == a && l.b == b) || (l.a == b && l.b == a)) return l.conductance_W_per_K > 0.0;
  return false;
}

}  // namespace

MissingLinkEffect::MissingLinkEffect()
    : Effect("thermal.missing_link", EffectKind::kThermal, {ConductanceParameter(0.005)}) {}

std::vector<std::string> MissingLinkEffect::Targets(const TargetSpace& space) const {
  std::vector<std::string> out;
  for (const auto& pair : NodePairs(space.gyro, space.nodes, true))
    if (!HasLink(space.gyro, pair)) out.push_back(pair);
  return out;
}

void MissingLinkEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  const auto [a, b] = ResolvePair(gyro, target, true);
  gyro.network.links.push_back({a, b, p.at("conductance_W_per_K")});
}

}  // namespace rlg::sim
