#include "io/gyro_toml.h"

#include <cmath>
#include <fmt/format.h>
#include <ostream>
#include <stdexcept>

#include "io/atomic_output.h"
#include "sim/effect_registry.h"
#include "sim/errors.h"
#include "sim/gyro_compare.h"

namespace rlg::io {

using sim::BiasParams;
using sim::Effect;
using sim::FindEffect;
using sim::GyroConfig;
using sim::GyroNoiseParams;
using sim::NetworkSpec;
using sim::SensorSpec;
using sim::kAmbient;

namespace {

[[noreturn]] void Refuse(const GyroConfig& gyro, const std::string& why) {
  throw std::invalid_argument(fmt::format("cannot write gyro '{}' as a gyro file: {}", gyro.name, why));
}

/// The shortest decimal that reads back to the same double, always a TOML float.
std::string Float(const GyroConfig& gyro, const std::string& field, double v) {
  if (!std::isfinite(v)) Refuse(gyro, fmt::format("{} is {}, not a finite number", field, v));
  std::string s = fmt::format("{}", v);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";
  return s;
}

/// A TOML basic string: quotes, backslashes and control characters escaped; other bytes
/// (UTF-8) as they are.
std::string Quoted(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += ch;
    } else if (c < 0x20 || c == 0x7f) {
      out += fmt::format("\\u{:04X}", c);
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

/// A key: bare when TOML allows it (letters, digits, '_' and '-'), quoted otherwise.
std::string Key(const std::string& k) {
  const bool bare = !k.empty() && k.find_first_not_of("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-") ==
                                      std::string::npos;
  return bare ? k : Quoted(k);
}

std::string NodeName(const GyroConfig& gyro, const std::string& field, int i, bool allow_ambient) {
  if (allow_ambient && i == kAmbient) return "ambient";
  if (i < 0 || i >= static_cast<int>(gyro.network.nodes.size())) {
    Refuse(gyro, fmt::format("{} is node {}, which the gyro without its effects does not have", field, i));
  }
  return gyro.network.nodes[static_cast<size_t>(i)].name;
}

/// `between = ["a", "b"]` of a link or radiation entry; the loader puts ambient second.
std::string Between(const GyroConfig& gyro, const std::string& field, int a, int b, bool allow_ambient) {
  if (a == kAmbient) Refuse(gyro, fmt::format("{} starts at ambient; a gyro file puts ambient second", field));
  return fmt::format("between = [{}, {}]\n", Quoted(NodeName(gyro, field, a, false)),
                     Quoted(NodeName(gyro, field, b, allow_ambient)));
}

/// The gyro without its catalog effects: what ApplyEffect appended is dropped (each effect says
/// what, Effect::AppendsToNetwork: a missing mass's node and two links, ..., always at the end)
/// and every field only an effect sets is reset to its default. The caller checks that applying
/// the effects again gives the gyro back.
GyroConfig WithoutEffects(const GyroConfig& gyro) {
  GyroConfig base = gyro;
  base.effects.clear();
  size_t nodes = 0, links = 0, radiation = 0;
  for (const auto& e : gyro.effects) {
    const Effect* effect = FindEffect(e.name);
    if (effect == nullptr) Refuse(gyro, fmt::format("'{}' is not an effect of the catalog", e.name));
    const Effect::Appended added = effect->AppendsToNetwork();
    nodes += added.nodes;
    links += added.links;
    radiation += added.radiation;
  }
  NetworkSpec& net = base.network;
  if (nodes > net.nodes.size() || links > net.links.size() || radiation > net.radiation.size()) {
    Refuse(gyro, "its effects add more nodes, links or radiation entries than it has");
  }
  net.nodes.resize(net.nodes.size() - nodes);
  net.links.resize(net.links.size() - links);
  net.radiation.resize(net.radiation.size() - radiation);
  const NetworkSpec::Source plain_source;
  for (auto& s : net.sources) {
    s.drift_node = plain_source.drift_node;
    s.drift_per_K = plain_source.drift_per_K;
    s.drift_reference_C = plain_source.drift_reference_C;
  }
  const SensorSpec plain_sensor;
  for (auto& s : base.sensors) {
    s.offset_C = plain_sensor.offset_C;
    s.lag_time_constants_s = plain_sensor.lag_time_constants_s;
  }
  const BiasParams plain_bias;
  BiasParams& b = base.bias;
  b.rate_terms = plain_bias.rate_terms;
  b.extra_gradients = plain_bias.extra_gradients;
  b.hysteresis = plain_bias.hysteresis;
  b.play = plain_bias.play;
  b.mode_hops = plain_bias.mode_hops;
  b.mode_hop_step_dph = plain_bias.mode_hop_step_dph;
  b.mode_hop_range_modes = plain_bias.mode_hop_range_modes;
  b.mode_spacing_C = plain_bias.mode_spacing_C;
  b.mode_hop_centre_C = plain_bias.mode_hop_centre_C;
  return base;
}

/// The base that, with gyro.effects applied, is `gyro`; refuses when there is none.
GyroConfig ExpressibleBase(const GyroConfig& gyro) {
  if (!gyro.network.followers.empty()) {
    Refuse(gyro, "its network holds sensor-lag followers, which the simulator builds from the sensors' lags");
  }
  GyroConfig base = WithoutEffects(gyro);
  GyroConfig again = base;
  for (size_t i = 0; i < gyro.effects.size(); ++i) {
    try {
      ApplyEffect(gyro.effects[i], again);
    } catch (const InputError& e) {
      Refuse(gyro, fmt::format("effects[{}] ({}) does not apply to the gyro without its effects: {}", i,
                               gyro.effects[i].name, e.what()));
    }
  }
  if (const std::string diff = GyroDifference(again, gyro); !diff.empty()) {
    Refuse(gyro, fmt::format("it is not a gyro file's plain keys plus its [[effects]] (a field only an effect sets, "
                             "or one changed after an effect was applied): read back, it would differ in {} "
                             "(read back != this gyro)",
                             diff));
  }
  for (size_t i = 1; i < base.sensors.size(); ++i) {
    if (!(base.sensors[i - 1].channel < base.sensors[i].channel)) {
      Refuse(gyro, fmt::format("sensors '{}' before '{}': the loader reads sensors in the byte order of their channels",
                               base.sensors[i - 1].channel, base.sensors[i].channel));
    }
  }
  return base;
}

/// The thermal network's tables of Text: [[nodes]], [[links]], [[radiation]], [[sources]] and
/// [sensors.*] of `base`, the expressible form of `gyro`.
std::string NetworkText(const GyroConfig& gyro, const GyroConfig& base) {
  const NetworkSpec& net = base.network;
  auto num = [&](const std::string& field, double v) { return Float(gyro, field, v); };
  std::string t;
  for (size_t i = 0; i < net.nodes.size(); ++i) {
    const auto& n = net.nodes[i];
    t += fmt::format("\n[[nodes]]\nname = {}\nheat_capacity_J_per_K = {}\n", Quoted(n.name),
                     num(fmt::format("nodes[{}].heat_capacity_J_per_K", i), n.heat_capacity_J_per_K));
  }
  for (size_t i = 0; i < net.links.size(); ++i) {
    const auto& l = net.links[i];
    const std::string field = fmt::format("links[{}]", i);
    t += "\n[[links]]\n" + Between(base, field, l.a, l.b, true);
    t += fmt::format("conductance_W_per_K = {}\n", num(field + ".conductance_W_per_K", l.conductance_W_per_K));
  }
  for (size_t i = 0; i < net.radiation.size(); ++i) {
    const auto& r = net.radiation[i];
    const std::string field = fmt::format("radiation[{}]", i);
    t += "\n[[radiation]]\n" + Between(base, field, r.a, r.b, true);
    t += fmt::format("emissivity_area_m2 = {}\n", num(field + ".emissivity_area_m2", r.emissivity_area_m2));
  }
  for (size_t i = 0; i < net.sources.size(); ++i) {
    const auto& s = net.sources[i];
    const std::string field = fmt::format("sources[{}] ({})", i, s.name);
    t += fmt::format("\n[[sources]]\nname = {}\npower_W = {}\ndriven_by_data = {}\ngain = {}\nshares = {{ ",
                     Quoted(s.name), num(field + ".power_W", s.power_W), s.driven_by_data ? "true" : "false",
                     num(field + ".gain", s.gain));
    for (size_t k = 0; k < s.shares.size(); ++k) {
      const std::string node = NodeName(base, fmt::format("{}.shares[{}]", field, k), s.shares[k].first, false);
      if (k > 0 && !(NodeName(base, field, s.shares[k - 1].first, false) < node)) {
        Refuse(gyro, fmt::format("{}.shares: '{}' after '{}': the loader reads shares in the byte order of the node "
                                 "names",
                                 field, node, NodeName(base, field, s.shares[k - 1].first, false)));
      }
      t += fmt::format("{}{} = {}", k > 0 ? ", " : "", Key(node), num(field + ".shares." + node, s.shares[k].second));
    }
    t += " }\n";
  }
  for (const auto& s : base.sensors) {
    const std::string field = "sensors." + s.channel;
    t += fmt::format("\n[sensors.{}]\nnode = {}\nnoise_C = {}\nresolution_C = {}\n", Key(s.channel),
                     Quoted(NodeName(base, field + ".node", s.node, false)), num(field + ".noise_C", s.noise.sigma_C),
                     num(field + ".resolution_C", s.noise.resolution_C));
  }
  return t;
}

/// Text's [bias] and its [[bias.langmuir_gradient]].
std::string BiasText(const GyroConfig& gyro, const GyroConfig& base) {
  auto num = [&](const std::string& field, double v) { return Float(gyro, field, v); };
  std::string t;
  const BiasParams& b = base.bias;
  t += fmt::format("\n[bias]\nnode = {}\n", Quoted(NodeName(base, "bias.node", b.node, false)));
  const std::pair<const char*, double> bias_numbers[] = {
      {"reference_C", b.reference_C},
      {"b0_dph", b.b0_dph},
      {"b1_dph_per_C", b.b1_dph_per_C},
      {"b2_dph_per_C2", b.b2_dph_per_C2},
      {"langmuir_current_imbalance_mA", b.langmuir_current_imbalance_mA},
      {"langmuir_dph_per_mA", b.langmuir_dph_per_mA},
      {"langmuir_temperature_coeff_per_C", b.langmuir_temperature_coeff_per_C},
      {"path_length_m", b.path_length_m},
      {"cte_per_C", b.cte_per_C},
      {"wavelength_m", b.wavelength_m},
      {"plc_dph_per_wavelength", b.plc_dph_per_wavelength},
  };
  for (const auto& [key, v] : bias_numbers) t += fmt::format("{} = {}\n", key, num(std::string("bias.") + key, v));
  for (size_t i = 0; i < b.langmuir_gradients.size(); ++i) {
    const auto& g = b.langmuir_gradients[i];
    const std::string field = fmt::format("bias.langmuir_gradient[{}]", i);
    t += "\n[[bias.langmuir_gradient]]\n" + Between(base, field, g.a, g.b, false);
    t += fmt::format("k_dph_per_C = {}\n", num(field + ".k_dph_per_C", g.k_dph_per_C));
  }
  return t;
}

/// Text's [noise].
std::string NoiseText(const GyroConfig& gyro, const GyroConfig& base) {
  auto num = [&](const std::string& field, double v) { return Float(gyro, field, v); };
  std::string t;
  const GyroNoiseParams& n = base.noise;
  const char* model = nullptr;
  switch (n.instability_model) {
    case GyroNoiseParams::InstabilityModel::kFlicker: model = "flicker"; break;
    case GyroNoiseParams::InstabilityModel::kGaussMarkov: model = "gauss_markov"; break;
  }
  if (!model) Refuse(gyro, "noise.instability_model is neither flicker nor gauss_markov");
  t += fmt::format("\n[noise]\narw_deg_per_sqrt_h = {}\nbias_instability_dph = {}\ninstability_model = \"{}\"\n",
                   num("noise.arw_deg_per_sqrt_h", n.arw_deg_per_sqrt_h),
                   num("noise.bias_instability_dph", n.bias_instability_dph), model);
  t += fmt::format("gauss_markov_time_s = {}\nrrw_deg_per_h_per_sqrt_h = {}\nquantization_arcsec = {}\n",
                   num("noise.gauss_markov_time_s", n.gauss_markov_time_s),
                   num("noise.rrw_deg_per_h_per_sqrt_h", n.rrw_deg_per_h_per_sqrt_h),
                   num("noise.quantization_arcsec", n.quantization_arcsec));
  t += fmt::format("turn_on_sigma_dph = {}\n", num("noise.turn_on_sigma_dph", n.turn_on_sigma_dph));
  return t;
}

std::string Text(const GyroConfig& gyro) {
  const GyroConfig base = ExpressibleBase(gyro);
  auto num = [&](const std::string& field, double v) { return Float(gyro, field, v); };
  std::string t;
  t += fmt::format("# Gyro file written by rlgtherm: the gyro {}, with every key of scenarios/README.md (\"Gyro file\")\n",
                   Quoted(gyro.name));
  t += "# written out, defaults included; each number reads back to the same double.\n";
  if (!gyro.effects.empty()) {
    t += "# The keys describe the gyro without its catalog effects; the [[effects]] at the end are applied\n";
    t += "# to it on reading, in order (scenarios/README.md, \"Effects\").\n";
  }
  t += fmt::format("\nname = {}\n", Quoted(base.name));

  t += NetworkText(gyro, base);
  t += BiasText(gyro, base);
  t += NoiseText(gyro, base);
  t += fmt::format("\n[calibration]\nrelative_uncertainty = {}\n",
                   num("calibration_uncertainty", base.calibration_uncertainty));

  for (size_t i = 0; i < gyro.effects.size(); ++i) {
    const auto& e = gyro.effects[i];
    t += fmt::format("\n[[effects]]\nname = {}\ntarget = {}\n", Quoted(e.name), Quoted(e.target));
    for (const auto& [key, v] : e.parameters) {
      t += fmt::format("{} = {}\n", Key(key), num(fmt::format("effects[{}] ({}).{}", i, e.name, key), v));
    }
  }
  return t;
}

}  // namespace

void WriteGyroToml(const GyroConfig& gyro, std::ostream& out) { out << Text(gyro); }

void SaveGyro(const GyroConfig& gyro, const std::string& path) {
  const std::string text = Text(gyro);  // a refusal touches no file
  WriteFileAtomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace rlg::io
