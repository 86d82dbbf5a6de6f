#include "diagnosis/network/model.h"

#include "sim/effect_registry.h"
#include "sim/thermal_network.h"

namespace rlg::diagnosis {

using sim::GyroConfig;

std::vector<BaseKnob> BaselineKnobs(const GyroConfig& g) {
  std::vector<BaseKnob> k;
  const auto& net = g.network;
  auto node_name = [&](int i) { return i == sim::kAmbient ? std::string("ambient") : net.nodes[i].name; };
  for (size_t i = 0; i < net.nodes.size(); ++i) {
    k.push_back({"C:" + net.nodes[i].name, net.nodes[i].heat_capacity_J_per_K,
                 [i](GyroConfig& c, double v) { c.network.nodes[i].heat_capacity_J_per_K = v; }, KnobKind::kHeatCapacity});
  }
  for (size_t l = 0; l < net.links.size(); ++l) {
    if (net.links[l].conductance_W_per_K <= 0.0) continue;
    k.push_back({"G:" + node_name(net.links[l].a) + "-" + node_name(net.links[l].b), net.links[l].conductance_W_per_K,
                 [l](GyroConfig& c, double v) { c.network.links[l].conductance_W_per_K = v; }, KnobKind::kConductance,
                 net.links[l].b == sim::kAmbient || net.links[l].a == sim::kAmbient});
  }
  for (size_t r = 0; r < net.radiation.size(); ++r) {
    if (net.radiation[r].emissivity_area_m2 <= 0.0) continue;
    k.push_back({"eA:" + node_name(net.radiation[r].a) + "-" + node_name(net.radiation[r].b),
                 net.radiation[r].emissivity_area_m2,
                 [r](GyroConfig& c, double v) { c.network.radiation[r].emissivity_area_m2 = v; }, KnobKind::kRadiation,
                 net.radiation[r].b == sim::kAmbient || net.radiation[r].a == sim::kAmbient});
  }
  for (size_t s = 0; s < net.sources.size(); ++s) {
    // A source switched off (no power, or a gain of 0 in the file) has nothing to calibrate;
    // its log-gain would start at -infinity.
    if ((!net.sources[s].driven_by_data && net.sources[s].power_W <= 0.0) || !(net.sources[s].gain > 0.0)) continue;
    // The file's gain (1 unless a calibrated file, e.g. an extended-gyro.toml, sets it).
    k.push_back({"gain:" + net.sources[s].name, net.sources[s].gain, [s](GyroConfig& c, double v) {
                   c.network.sources[s].gain = v;
                 }, KnobKind::kGain});
  }
  return k;
}

GyroConfig Build(const GyroConfig& nominal, const std::vector<BaseKnob>& knobs, const Model& m) {
  GyroConfig g = nominal;
  for (size_t i = 0; i < knobs.size(); ++i) knobs[i].set(g, m.base[i]);
  for (const auto& e : m.effects) sim::ApplyEffect(e, g);
  return g;
}

}  // namespace rlg::diagnosis
