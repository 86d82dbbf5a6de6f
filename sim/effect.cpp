#include "sim/effect.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::sim {

Effect::Effect(std::string name, EffectKind kind, std::vector<EffectParameter> parameters)
    : name_(std::move(name)), kind_(kind), parameters_(std::move(parameters)) {}

const EffectParameter* Effect::FindParameter(const std::string& name) const {
  for (const auto& p : parameters_)
    if (p.name == name) return &p;
  return nullptr;
}

std::string Effect::CanonicalTarget(const GyroConfig& g, const std::string& target) const {
  return kind_ == EffectKind::kSensor ? target : CanonicalNodeTarget(g, target);
}

std::vector<RangeViolation> Effect::OutsidePlausibleRange(const ParameterMap& applied) const {
  std::vector<RangeViolation> out;
  for (const auto& p : parameters_) {
    if (p.reference) continue;
    const auto it = applied.find(p.name);
    if (it == applied.end()) continue;
    if (!(it->second >= p.lo && it->second <= p.hi)) out.push_back({&p, it->second});
  }
  return out;
}

int Effect::RequireSensor(const GyroConfig& gyro, const std::string& channel) const {
  const int s = gyro.FindSensor(channel);
  if (s < 0) throw InputError(fmt::format("{}: '{}' is not a sensor channel of this gyro", name_, channel));
  return s;
}

EffectParameter ConductanceParameter() {
  // The low end is the weakest path two bodies of a gyro share, not a size below which a link
  // stops being physical: a 0.1 mm copper sensor lead over 5 cm conducts 400 W/(m K) x 7.9e-9 m^2
  // / 0.05 m = 6.3e-5 W/K, a 0.1 mm constantan thermocouple lead over 10 cm (22 W/(m K)) 1.7e-6.
  return {"conductance_W_per_K", "W/K", true, 1e-6, 10.0,
          "[est] a thin sensor lead (0.1 mm constantan over 10 cm: 1.7e-6 W/K; copper over 5 cm: 6e-5 W/K) to a "
          "bolted metal joint (the default gyro's case to its fixture plate: 8 W/K; its block mounts 0.42 W/K)",
          0.0, limits::kMaxConductance, std::nullopt};
}

int ResolveNode(const GyroConfig& gyro, const std::string& name, bool allow_ambient) {
  const int i = gyro.network.FindNode(name);
  if (i >= 0 || (allow_ambient && i == kAmbient)) return i;
  const int s = gyro.FindSensor(name);
  if (s >= 0) return gyro.sensors[s].node;
  throw InputError(fmt::format("'{}' is not a node{} or a sensor channel of this gyro", name,
                               allow_ambient ? ", 'ambient'," : ""));
}

std::pair<int, int> ResolvePair(const GyroConfig& gyro, const std::string& target, bool allow_ambient) {
  const auto dash = target.find('-');
  if (dash == std::string::npos) {
    throw InputError(fmt::format("target '{}' must name two nodes joined by '-', e.g. 'anode-cabinet'", target));
  }
  const int a = ResolveNode(gyro, target.substr(0, dash), false);
  const int b = ResolveNode(gyro, target.substr(dash + 1), allow_ambient);
  if (a == b) throw InputError(fmt::format("target '{}' names the same node twice", target));
  return {a, b};
}

std::vector<std::string> NodePairs(const GyroConfig& g, int nodes, bool with_ambient) {
  std::vector<std::string> out;
  const auto& n = g.network.nodes;
  for (int a = 0; a < nodes; ++a) {
    for (int b = a + 1; b < nodes; ++b) out.push_back(n[a].name + "-" + n[b].name);
    if (with_ambient) out.push_back(n[a].name + "-ambient");
  }
  return out;
}

std::string CanonicalNodeTarget(const GyroConfig& g, const std::string& target) {
  auto node = [&](const std::string& name) {
    if (name == "ambient" || g.network.FindNode(name) >= 0) return name;
    const int s = g.FindSensor(name);
    return s >= 0 ? g.network.nodes[g.sensors[s].node].name : name;
  };
  const auto dash = target.find('-');
  if (dash == std::string::npos) return node(target);
  std::string a = node(target.substr(0, dash)), b = node(target.substr(dash + 1));
  if (b != "ambient" && b < a) std::swap(a, b);
  return a + "-" + b;
}

std::string NodeTarget(const GyroConfig& g, int node) {
  for (const auto& s : g.sensors)
    if (s.node == node && s.lag_time_constants_s.empty()) return s.channel;
  return g.network.nodes[node].name;
}

}  // namespace rlg::sim
