// The thermal effects' searches (effect_search.h): where each is tried and where its fit starts.

#include "diagnosis/catalog/searches.h"

namespace rlg::diagnosis::catalog {
namespace {

using Fit = ParameterSearch::Fit;

/// thermal.missing_mass: every pair of nodes.
class MissingMass final : public EffectSearch {
 public:
  // The capacity trades against the conductance: a factor 10 around 100 J/K keeps it from
  // running off to a reservoir.
  MissingMass()
      : EffectSearch("thermal.missing_mass",
                     {{"heat_capacity_J_per_K", {100.0, Fit::kShape, 10.0}}, {"conductance_W_per_K", {0.02}}}) {}
  std::vector<std::string> Targets(const TargetSpace& space) const override {
    return sim::NodePairs(space.gyro, space.nodes, false);
  }
};

/// Whether the first link between the pair's ends (either way round) conducts.
bool HasLink(const sim::GyroConfig& g, const std::string& pair) {
  const auto dash = pair.find('-');
  const int a = g.network.FindNode(pair.substr(0, dash)), b = g.network.FindNode(pair.substr(dash + 1));
  for (const auto& l : g.network.links)
    if ((l.a == a && l.b == b) || (l.a == b && l.b == a)) return l.conductance_W_per_K > 0.0;
  return false;
}

/// thermal.missing_link: every pair of nodes, and every node with ambient, that has no
/// conducting link yet.
class MissingLink final : public EffectSearch {
 public:
  MissingLink() : EffectSearch("thermal.missing_link", {{"conductance_W_per_K", {0.005}}}) {}
  std::vector<std::string> Targets(const TargetSpace& space) const override {
    std::vector<std::string> out;
    for (const auto& pair : sim::NodePairs(space.gyro, space.nodes, true))
      if (!HasLink(space.gyro, pair)) out.push_back(pair);
    return out;
  }
};

bool Heated(const sim::GyroConfig& g, int node) {
  for (const auto& src : g.network.sources)
    for (const auto& sh : src.shares)
      if (sh.first == node && sh.second > 0.0) return true;
  return false;
}

/// thermal.power_drift: every node a heat source deposits power on.
class PowerDrift final : public EffectSearch {
 public:
  PowerDrift() : EffectSearch("thermal.power_drift", {{"g_per_C", {0.002}}}) {}
  std::vector<std::string> Targets(const TargetSpace& space) const override {
    std::vector<std::string> out;
    for (int node = 0; node < space.nodes; ++node)
      if (Heated(space.gyro, node)) out.push_back(space.gyro.network.nodes[node].name);
    return out;
  }
};

/// thermal.radiation: every pair of nodes and every node with ambient.
class Radiation final : public EffectSearch {
 public:
  Radiation() : EffectSearch("thermal.radiation", {{"emissivity_area_m2", {0.001}}}) {}
  std::vector<std::string> Targets(const TargetSpace& space) const override {
    return sim::NodePairs(space.gyro, space.nodes, true);
  }
};

}  // namespace

std::unique_ptr<const EffectSearch> MissingMassSearch() { return std::make_unique<MissingMass>(); }
std::unique_ptr<const EffectSearch> MissingLinkSearch() { return std::make_unique<MissingLink>(); }
std::unique_ptr<const EffectSearch> PowerDriftSearch() { return std::make_unique<PowerDrift>(); }
std::unique_ptr<const EffectSearch> RadiationSearch() { return std::make_unique<Radiation>(); }

}  // namespace rlg::diagnosis::catalog
