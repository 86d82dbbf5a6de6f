#include "sim/gyro_parameters.h"

#include <limits>
#include <map>

#include "sim/effect_registry.h"

namespace rlg::sim {
namespace {

constexpr double kFree = -std::numeric_limits<double>::infinity();

std::string NodeName(const NetworkSpec& net, int i) { return i == kAmbient ? "ambient" : net.nodes[static_cast<size_t>(i)].name; }

/// A [bias] or [noise] scalar: a pointer to the member of its struct.
template <typename Struct>
GyroParameter Member(std::string name, double lower, Struct GyroConfig::*part, double Struct::*field) {
  return {std::move(name), lower, false, [part, field](const GyroConfig& g) { return g.*part.*field; },
          [part, field](GyroConfig& g, double v) { g.*part.*field = v; }};
}

/// Where a bias effect keeps its terms: the j-th effect of a name is the j-th entry of its list
/// (the lists exist only as effects, io/gyro_toml.h), and the field of each parameter.
template <typename Bias>
auto EffectField(Bias& b, const std::string& effect, size_t j, const std::string& parameter) -> decltype(&b.b0_dph) {
  if (effect == "bias.temperature_rate" && parameter == "k_dph_per_C_per_min") return &b.rate_terms.at(j).k_dph_per_C_per_min;
  if (effect == "bias.gradient" && parameter == "k_dph_per_C") return &b.extra_gradients.at(j).k_dph_per_C;
  if (effect == "bias.hysteresis" && parameter == "k_heating_dph_per_C") return &b.hysteresis.at(j).k_heating_dph_per_C;
  if (effect == "bias.hysteresis" && parameter == "k_cooling_dph_per_C") return &b.hysteresis.at(j).k_cooling_dph_per_C;
  if (effect == "bias.play" && parameter == "k_dph_per_C") return &b.play.at(j).k_dph_per_C;
  if (effect == "bias.play" && parameter == "width_C") return &b.play.at(j).width_C;
  return nullptr;
}

/// The spreadable parameters of the gyro's bias effects, in [[effects]] order.
void EffectParameters(const GyroConfig& gyro, std::vector<GyroParameter>& out) {
  std::map<std::string, size_t> seen;  // effects of each name so far: j
  for (size_t i = 0; i < gyro.effects.size(); ++i) {
    const EffectSpec& e = gyro.effects[i];
    const size_t j = seen[e.name]++;
    const Effect* effect = FindEffect(e.name);
    if (effect == nullptr) continue;
    for (const auto& p : effect->parameters()) {
      if (p.reference) continue;
      // Only the bias effects' own terms have a field (none for thermal and sensor effects).
      if (EffectField(gyro.bias, e.name, j, p.name) == nullptr) continue;
      const std::string key = p.name, name = e.name;
      GyroParameter q{e.name + "." + e.target + "." + p.name, p.file_lo, p.positive && p.file_lo <= 0.0,
                      [name, j, key](const GyroConfig& g) { return *EffectField(g.bias, name, j, key); },
                      [name, i, j, key](GyroConfig& g, double v) {
                        *EffectField(g.bias, name, j, key) = v;
                        g.effects.at(i).parameters[key] = v;
                      }};
      q.upper = p.file_hi;
      out.push_back(std::move(q));
    }
  }
}

}  // namespace

std::vector<GyroParameter> GyroParameters(const GyroConfig& gyro) {
  std::vector<GyroParameter> out;
  const NetworkSpec& net = gyro.network;
  for (size_t i = 0; i < net.nodes.size(); ++i) {
    out.push_back({"nodes." + net.nodes[i].name + ".heat_capacity_J_per_K", 0.0, true,
                   [i](const GyroConfig& g) { return g.network.nodes[i].heat_capacity_J_per_K; },
                   [i](GyroConfig& g, double v) { g.network.nodes[i].heat_capacity_J_per_K = v; }});
  }
  for (size_t l = 0; l < net.links.size(); ++l) {
    out.push_back({"links." + NodeName(net, net.links[l].a) + "-" + NodeName(net, net.links[l].b) + ".conductance_W_per_K",
                   0.0, false, [l](const GyroConfig& g) { return g.network.links[l].conductance_W_per_K; },
                   [l](GyroConfig& g, double v) { g.network.links[l].conductance_W_per_K = v; }});
  }
  for (size_t r = 0; r < net.radiation.size(); ++r) {
    out.push_back({"radiation." + NodeName(net, net.radiation[r].a) + "-" + NodeName(net, net.radiation[r].b) +
                       ".emissivity_area_m2",
                   0.0, false, [r](const GyroConfig& g) { return g.network.radiation[r].emissivity_area_m2; },
                   [r](GyroConfig& g, double v) { g.network.radiation[r].emissivity_area_m2 = v; }});
  }
  for (size_t s = 0; s < net.sources.size(); ++s) {
    out.push_back({"sources." + net.sources[s].name + ".power_W", 0.0, false,
                   [s](const GyroConfig& g) { return g.network.sources[s].power_W; },
                   [s](GyroConfig& g, double v) { g.network.sources[s].power_W = v; }});
    out.push_back({"sources." + net.sources[s].name + ".gain", 0.0, false,
                   [s](const GyroConfig& g) { return g.network.sources[s].gain; },
                   [s](GyroConfig& g, double v) { g.network.sources[s].gain = v; }});
  }
  for (size_t c = 0; c < gyro.sensors.size(); ++c) {
    const std::string prefix = "sensors." + gyro.sensors[c].channel;
    out.push_back({prefix + ".noise_C", 0.0, false, [c](const GyroConfig& g) { return g.sensors[c].noise.sigma_C; },
                   [c](GyroConfig& g, double v) { g.sensors[c].noise.sigma_C = v; }});
    out.push_back({prefix + ".offset_C", kFree, false, [c](const GyroConfig& g) { return g.sensors[c].offset_C; },
                   [c](GyroConfig& g, double v) { g.sensors[c].offset_C = v; }});
  }
  using B = BiasParams;
  out.push_back(Member("bias.b0_dph", kFree, &GyroConfig::bias, &B::b0_dph));
  out.push_back(Member("bias.b1_dph_per_C", kFree, &GyroConfig::bias, &B::b1_dph_per_C));
  out.push_back(Member("bias.b2_dph_per_C2", kFree, &GyroConfig::bias, &B::b2_dph_per_C2));
  out.push_back(Member("bias.langmuir_current_imbalance_mA", kFree, &GyroConfig::bias, &B::langmuir_current_imbalance_mA));
  out.push_back(Member("bias.langmuir_dph_per_mA", kFree, &GyroConfig::bias, &B::langmuir_dph_per_mA));
  out.push_back(Member("bias.langmuir_temperature_coeff_per_C", kFree, &GyroConfig::bias,
                       &B::langmuir_temperature_coeff_per_C));
  out.push_back(Member("bias.plc_dph_per_wavelength", kFree, &GyroConfig::bias, &B::plc_dph_per_wavelength));
  out.push_back(Member("bias.cte_per_C", kFree, &GyroConfig::bias, &B::cte_per_C));
  GyroParameter length = Member("bias.path_length_m", 0.0, &GyroConfig::bias, &B::path_length_m);
  length.lower_open = true;
  out.push_back(std::move(length));
  for (size_t k = 0; k < gyro.bias.langmuir_gradients.size(); ++k) {
    const auto& gr = gyro.bias.langmuir_gradients[k];
    out.push_back({"bias.langmuir_gradient." + NodeName(net, gr.a) + "-" + NodeName(net, gr.b) + ".k_dph_per_C", kFree,
                   false, [k](const GyroConfig& g) { return g.bias.langmuir_gradients[k].k_dph_per_C; },
                   [k](GyroConfig& g, double v) { g.bias.langmuir_gradients[k].k_dph_per_C = v; }});
  }
  using N = GyroNoiseParams;
  out.push_back(Member("noise.arw_deg_per_sqrt_h", 0.0, &GyroConfig::noise, &N::arw_deg_per_sqrt_h));
  out.push_back(Member("noise.bias_instability_dph", 0.0, &GyroConfig::noise, &N::bias_instability_dph));
  out.push_back(Member("noise.rrw_deg_per_h_per_sqrt_h", 0.0, &GyroConfig::noise, &N::rrw_deg_per_h_per_sqrt_h));
  out.push_back(Member("noise.turn_on_sigma_dph", 0.0, &GyroConfig::noise, &N::turn_on_sigma_dph));
  EffectParameters(gyro, out);
  return out;
}

std::vector<GyroParameter> MatchParameters(const GyroConfig& gyro, const std::string& pattern) {
  std::vector<GyroParameter> out;
  const size_t star = pattern.find('*');
  for (auto& p : GyroParameters(gyro)) {
    bool match = false;
    if (star == std::string::npos) {
      match = p.name == pattern;
    } else {
      // `*` stands for one name part: no dot in what it covers.
      const std::string head = pattern.substr(0, star), tail = pattern.substr(star + 1);
      if (p.name.size() > head.size() + tail.size() && p.name.compare(0, head.size(), head) == 0 &&
          p.name.compare(p.name.size() - tail.size(), tail.size(), tail) == 0) {
        const std::string middle = p.name.substr(head.size(), p.name.size() - head.size() - tail.size());
        match = middle.find('.') == std::string::npos;
      }
    }
    if (match) out.push_back(std::move(p));
  }
  return out;
}

}  // namespace rlg::sim
