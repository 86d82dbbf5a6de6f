#include "sim/gyro.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <set>
#include <toml++/toml.h>

#include "sim/errors.h"
#include "sim/limits.h"
#include "sim/toml_reader.h"

namespace rlg::sim {
namespace {

// Physical ranges of gyro parameters: sim/limits.h.
namespace range = limits;

/// Allowed [lo, hi] of an effect parameter read from a file (ReadAndApplyEffects).
std::pair<double, double> EffectParameterRange(const std::string& key) {
  using namespace range;
  if (key == "heat_capacity_J_per_K") return {kMinCapacity, kMaxCapacity};
  if (key == "conductance_W_per_K") return {0.0, kMaxConductance};
  if (key == "emissivity_area_m2") return {0.0, kMaxEmissivityArea};
  if (key == "g_per_C") return {-kMaxRelativePerC, kMaxRelativePerC};
  if (key == "reference_C") return {kMinTemperature_C, kMaxTemperature_C};
  if (key == "time_constant_s") return {kMinLag, kMaxLag};
  if (key == "offset_C") return {-kMaxOffset, kMaxOffset};
  if (key == "k_dph_per_C_per_min") return {-kMaxBiasPerRate, kMaxBiasPerRate};
  if (key == "step_dph") return {-kMaxNoise_dph, kMaxNoise_dph};
  if (key == "range_modes") return {0.0, kMaxRangeModes};
  if (key == "mode_spacing_C") return {0.0, kTemperatureSpan_C};
  if (key.size() > 9 && key.substr(key.size() - 9) == "dph_per_C") return {-kMaxBiasPerC, kMaxBiasPerC};
  return {-INFINITY, INFINITY};  // unknown keys are refused by ApplyEffect
}

struct EffectDef {
  std::string name;
  enum class Target { kNode, kPair, kPairOrAmbient, kChannel } target;
  std::vector<std::pair<std::string, double>> parameters;  // NaN default = required
};

const std::vector<EffectDef>& EffectDefs() {
  const double req = NAN;
  static const std::vector<EffectDef> defs = {
      {"thermal.missing_mass", EffectDef::Target::kPair, {{"heat_capacity_J_per_K", req}, {"conductance_W_per_K", req}}},
      {"thermal.missing_link", EffectDef::Target::kPairOrAmbient, {{"conductance_W_per_K", req}}},
      {"thermal.power_drift", EffectDef::Target::kNode, {{"g_per_C", req}, {"reference_C", 20.0}}},
      {"thermal.radiation", EffectDef::Target::kPairOrAmbient, {{"emissivity_area_m2", req}}},
      {"sensor.lag", EffectDef::Target::kChannel, {{"time_constant_s", req}}},
      {"sensor.offset", EffectDef::Target::kChannel, {{"offset_C", req}}},
      {"bias.temperature_rate", EffectDef::Target::kNode, {{"k_dph_per_C_per_min", req}}},
      {"bias.gradient", EffectDef::Target::kPair, {{"k_dph_per_C", req}}},
      {"bias.hysteresis", EffectDef::Target::kNode, {{"k_heating_dph_per_C", req}, {"k_cooling_dph_per_C", req}}},
      {"bias.mode_hop", EffectDef::Target::kNode, {{"step_dph", req}, {"range_modes", 0.6}, {"mode_spacing_C", 0.0}}},
  };
  return defs;
}

/// A node by name, or the node a channel's sensor sits on.
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

int RequireNode(const TomlReader& t, const std::string& key, const NetworkSpec& net, bool allow_ambient) {
  const std::string name = t.String(key);
  const int i = net.FindNode(name);
  if (i >= 0 || (allow_ambient && i == kAmbient)) return i;
  t.Fail(key, fmt::format("'{}' is not a node of this gyro{}", name, allow_ambient ? " (nor 'ambient')" : ""));
}

std::pair<int, int> RequirePair(const TomlReader& t, const NetworkSpec& net, bool allow_ambient) {
  const auto names = t.Strings("between");
  if (names.size() != 2) t.Fail("between", "expected two names, e.g. [\"anode\", \"block\"]");
  auto find = [&](const std::string& n, bool amb) {
    const int i = net.FindNode(n);
    if (i >= 0 || (amb && i == kAmbient)) return i;
    t.Fail("between", fmt::format("'{}' is not a node of this gyro{}", n, amb ? " (nor 'ambient')" : ""));
  };
  const int a = find(names[0], allow_ambient && names[1] != "ambient");
  const int b = find(names[1], allow_ambient);
  if (a == b) t.Fail("between", "a link needs two different ends");
  if (a == kAmbient) return {b, a};
  return {a, b};
}

void ReadNetwork(const TomlReader& root, NetworkSpec& net) {
  for (const auto& t : root.ArrayOfTables("nodes")) {
    NetworkSpec::Node node;
    node.name = t.String("name");
    if (node.name.empty() || node.name.find('-') != std::string::npos || node.name == "ambient") {
      t.Fail("name", "node names must be non-empty, without '-', and not 'ambient'");
    }
    if (net.FindNode(node.name) >= 0) t.Fail("name", fmt::format("node '{}' is defined twice", node.name));
    const double c = t.Number("heat_capacity_J_per_K");
    if (!(c > 0.0)) t.Fail("heat_capacity_J_per_K", fmt::format("expected a heat capacity > 0 J/K, got {}", c));
    node.heat_capacity_J_per_K = t.InRange("heat_capacity_J_per_K", range::kMinCapacity, range::kMaxCapacity);
    t.Finish();
    net.nodes.push_back(node);
  }
  if (net.nodes.empty()) root.FailHere("a gyro needs at least one [[nodes]] entry");
  for (const auto& t : root.ArrayOfTables("links")) {
    const auto [a, b] = RequirePair(t, net, true);
    net.links.push_back({a, b, t.InRange("conductance_W_per_K", 0.0, range::kMaxConductance)});
    t.Finish();
  }
  for (const auto& t : root.ArrayOfTables("radiation")) {
    const auto [a, b] = RequirePair(t, net, true);
    net.radiation.push_back({a, b, t.InRange("emissivity_area_m2", 0.0, range::kMaxEmissivityArea)});
    t.Finish();
  }
  for (const auto& t : root.ArrayOfTables("sources")) {
    NetworkSpec::Source src;
    src.name = t.String("name");
    if (net.FindSource(src.name) >= 0) t.Fail("name", fmt::format("source '{}' is defined twice", src.name));
    src.driven_by_data = t.Bool("driven_by_data", false);
    src.power_W = t.InRange("power_W", -limits::kMaxAbsPower_W, limits::kMaxAbsPower_W, 0.0);
    const TomlReader shares = t.Table("shares");
    double total = 0.0;
    for (const auto& key : shares.Keys()) {
      const int node = net.FindNode(key);
      if (node < 0) shares.Fail(key, fmt::format("'{}' is not a node of this gyro", key));
      const double w = shares.Positive(key, true);
      src.shares.emplace_back(node, w);
      total += w;
    }
    if (src.shares.empty()) t.Fail("shares", "expected at least one node = fraction entry");
    if (std::abs(total - 1.0) > 1e-9) t.Fail("shares", fmt::format("fractions must add up to 1, they add up to {}", total));
    t.Finish();
    net.sources.push_back(src);
  }
}

void ReadSensors(const TomlReader& root, GyroConfig& gyro) {
  const TomlReader sensors = root.Table("sensors");
  for (const auto& channel : sensors.Keys()) {
    // The tidy CSV reads a column as a temperature when it is T<digit>... or T_<name>; T_amb is the ambient's.
    const bool named = channel.size() >= 2 && channel[0] == 'T' && (std::isdigit(static_cast<unsigned char>(channel[1])) ||
                                                                     channel[1] == '_');
    const bool plain = std::all_of(channel.begin(), channel.end(),
                                   [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; });
    if (!named || !plain || channel == "T_amb") {
      sensors.Fail(channel, "sensor channels are named T1, T2, ... or T_<name> (letters, digits, '_'; not T_amb)");
    }
    const TomlReader t = sensors.Table(channel);
    SensorSpec s;
    s.channel = channel;
    s.node = RequireNode(t, "node", gyro.network, false);
    s.noise.sigma_C = t.InRange("noise_C", 0.0, range::kMaxSensorNoise, 0.0);
    s.noise.resolution_C = t.Positive("resolution_C", 0.0, true);
    if (s.noise.resolution_C != 0.0) {
      s.noise.resolution_C = t.InRange("resolution_C", range::kMinResolution, range::kMaxResolution);
    }
    t.Finish();
    gyro.sensors.push_back(s);
  }
  if (gyro.FindSensor("T1") < 0) sensors.FailHere("sensor T1 (the gyro block) is required");
  sensors.Finish();
}

void ReadBias(const TomlReader& root, GyroConfig& gyro) {
  const auto bias_table = root.OptionalTable("bias");
  BiasParams& b = gyro.bias;
  if (!bias_table) {
    b.node = 0;
    return;
  }
  const TomlReader& t = *bias_table;
  b.node = RequireNode(t, "node", gyro.network, false);
  using namespace range;
  b.reference_C = t.InRange("reference_C", kMinTemperature_C, kMaxTemperature_C, 20.0);
  b.b0_dph = t.InRange("b0_dph", -kMaxAbsBias_dph, kMaxAbsBias_dph, 0.0);
  b.b1_dph_per_C = t.InRange("b1_dph_per_C", -kMaxBiasPerC, kMaxBiasPerC, 0.0);
  b.b2_dph_per_C2 = t.InRange("b2_dph_per_C2", -kMaxBiasPerC2, kMaxBiasPerC2, 0.0);
  b.langmuir_current_imbalance_mA =
      t.InRange("langmuir_current_imbalance_mA", -kMaxCurrentImbalance_mA, kMaxCurrentImbalance_mA, 0.0);
  b.langmuir_dph_per_mA = t.InRange("langmuir_dph_per_mA", -kMaxBiasPerMilliamp, kMaxBiasPerMilliamp, 0.0);
  b.langmuir_temperature_coeff_per_C =
      t.InRange("langmuir_temperature_coeff_per_C", -kMaxRelativePerC, kMaxRelativePerC, 0.0);
  for (const auto& g : t.ArrayOfTables("langmuir_gradient")) {
    const auto [a, bb] = RequirePair(g, gyro.network, false);
    b.langmuir_gradients.push_back({a, bb, g.InRange("k_dph_per_C", -kMaxBiasPerC, kMaxBiasPerC)});
    g.Finish();
  }
  b.path_length_m = t.InRange("path_length_m", kMinPath_m, kMaxPath_m, 0.43);
  b.cte_per_C = t.InRange("cte_per_C", kMinCte, kMaxCte, 5e-8);
  b.wavelength_m = t.InRange("wavelength_m", kMinWavelength_m, kMaxWavelength_m, 632.8e-9);
  b.plc_dph_per_wavelength = t.InRange("plc_dph_per_wavelength", -kMaxAbsBias_dph, kMaxAbsBias_dph, 0.0);
  t.Finish();
}

void ReadNoise(const TomlReader& root, GyroConfig& gyro) {
  const auto noise = root.OptionalTable("noise");
  if (!noise) return;
  GyroNoiseParams& n = gyro.noise;
  using namespace range;
  n.arw_deg_per_sqrt_h = noise->InRange("arw_deg_per_sqrt_h", 0.0, kMaxArw, 0.0);
  n.bias_instability_dph = noise->InRange("bias_instability_dph", 0.0, kMaxNoise_dph, 0.0);
  const std::string model = noise->String("instability_model", "flicker");
  if (model == "flicker") {
    n.instability_model = GyroNoiseParams::InstabilityModel::kFlicker;
  } else if (model == "gauss_markov") {
    n.instability_model = GyroNoiseParams::InstabilityModel::kGaussMarkov;
  } else {
    noise->Fail("instability_model", "expected \"flicker\" or \"gauss_markov\"");
  }
  n.gauss_markov_time_s = noise->InRange("gauss_markov_time_s", kMinCorrelation_s, kMaxCorrelation_s, 3600.0);
  n.rrw_deg_per_h_per_sqrt_h = noise->InRange("rrw_deg_per_h_per_sqrt_h", 0.0, kMaxNoise_dph, 0.0);
  n.quantization_arcsec = noise->Positive("quantization_arcsec", 0.0, true);
  if (n.quantization_arcsec != 0.0) n.quantization_arcsec = noise->InRange("quantization_arcsec", kMinQuantum, kMaxQuantum);
  n.turn_on_sigma_dph = noise->InRange("turn_on_sigma_dph", 0.0, kMaxNoise_dph, 0.0);
  noise->Finish();
}

}  // namespace

const std::vector<std::string>& EffectNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& d : EffectDefs()) v.push_back(d.name);
    return v;
  }();
  return names;
}

int GyroConfig::FindSensor(const std::string& channel) const {
  for (size_t i = 0; i < sensors.size(); ++i)
    if (sensors[i].channel == channel) return static_cast<int>(i);
  return -1;
}

void ApplyEffect(const EffectSpec& e, GyroConfig& gyro) {
  const EffectDef* def = nullptr;
  for (const auto& d : EffectDefs())
    if (d.name == e.name) def = &d;
  if (!def) {
    throw InputError(fmt::format("unknown effect '{}'; the catalog (scenarios/README.md, Effects) has: {}", e.name,
                                 fmt::join(EffectNames(), ", ")));
  }
  std::map<std::string, double> p;
  for (const auto& [key, dflt] : def->parameters) {
    auto it = e.parameters.find(key);
    if (it != e.parameters.end()) {
      p[key] = it->second;
    } else if (std::isnan(dflt)) {
      throw InputError(fmt::format("effect '{}' needs parameter '{}'", e.name, key));
    } else {
      p[key] = dflt;
    }
  }
  for (const auto& [key, v] : e.parameters) {
    if (!p.count(key)) throw InputError(fmt::format("effect '{}' has no parameter '{}'", e.name, key));
  }
  auto& net = gyro.network;
  auto& bias = gyro.bias;
  const std::string& n = e.name;
  if (n == "thermal.missing_mass") {
    const auto [a, b] = ResolvePair(gyro, e.target, false);
    if (!(p["heat_capacity_J_per_K"] > 0.0) || !(p["conductance_W_per_K"] > 0.0)) {
      throw InputError("thermal.missing_mass needs heat_capacity_J_per_K > 0 and conductance_W_per_K > 0");
    }
    const int m = static_cast<int>(net.nodes.size());
    net.nodes.push_back({net.nodes[a].name + "_" + net.nodes[b].name + "_mass", p["heat_capacity_J_per_K"]});
    net.links.push_back({a, m, p["conductance_W_per_K"]});
    net.links.push_back({m, b, p["conductance_W_per_K"]});
  } else if (n == "thermal.missing_link") {
    const auto [a, b] = ResolvePair(gyro, e.target, true);
    net.links.push_back({a, b, p["conductance_W_per_K"]});
  } else if (n == "thermal.radiation") {
    const auto [a, b] = ResolvePair(gyro, e.target, true);
    net.radiation.push_back({a, b, p["emissivity_area_m2"]});
  } else if (n == "thermal.power_drift") {
    const int node = ResolveNode(gyro, e.target, false);
    bool any = false;
    for (auto& src : net.sources) {
      for (const auto& sh : src.shares) {
        if (sh.first == node && sh.second > 0.0) any = true;
      }
      if (!any) continue;
      src.drift_node = node;
      src.drift_per_K = p["g_per_C"];
      src.drift_reference_C = p["reference_C"];
      break;
    }
    if (!any) throw InputError(fmt::format("thermal.power_drift: no heat source deposits power on '{}'", e.target));
  } else if (n == "sensor.lag" || n == "sensor.offset") {
    const int s = gyro.FindSensor(e.target);
    if (s < 0) throw InputError(fmt::format("{}: '{}' is not a sensor channel of this gyro", n, e.target));
    if (n == "sensor.lag") {
      if (!(p["time_constant_s"] > 0.0)) throw InputError("sensor.lag needs time_constant_s > 0");
      gyro.sensors[s].lag_time_constant_s = p["time_constant_s"];
    } else {
      gyro.sensors[s].offset_C += p["offset_C"];
    }
  } else if (n == "bias.temperature_rate") {
    bias.rate_terms.push_back({ResolveNode(gyro, e.target, false), p["k_dph_per_C_per_min"]});
  } else if (n == "bias.gradient") {
    const auto [a, b] = ResolvePair(gyro, e.target, false);
    bias.extra_gradients.push_back({a, b, p["k_dph_per_C"]});
  } else if (n == "bias.hysteresis") {
    bias.hysteresis.push_back({ResolveNode(gyro, e.target, false), p["k_heating_dph_per_C"], p["k_cooling_dph_per_C"]});
  } else if (n == "bias.mode_hop") {
    const int node = ResolveNode(gyro, e.target, false);
    if (node != bias.node) {
      throw InputError(fmt::format("bias.mode_hop acts on the bias node '{}' (the path-length control follows it)",
                                   net.nodes[bias.node].name));
    }
    if (!(p["range_modes"] > 0.5)) throw InputError("bias.mode_hop needs range_modes > 0.5");
    bias.mode_hops = true;
    bias.mode_hop_step_dph = p["step_dph"];
    bias.mode_hop_range_modes = p["range_modes"];
    if (p["mode_spacing_C"] > 0.0) bias.mode_spacing_C = p["mode_spacing_C"];
  }
  gyro.effects.push_back(e);
}

EffectSpec ReadEffect(const TomlReader& t) {
  EffectSpec e;
  e.name = t.String("name");
  e.target = t.String("target");
  for (const auto& key : t.Keys()) {
    if (key == "name" || key == "target") continue;
    const auto [lo, hi] = EffectParameterRange(key);
    e.parameters[key] = t.InRange(key, lo, hi);
  }
  t.Finish();
  return e;
}

void ReadAndApplyEffects(const TomlReader& root, GyroConfig& gyro) {
  for (const auto& t : root.ArrayOfTables("effects")) {
    const EffectSpec e = ReadEffect(t);
    try {
      ApplyEffect(e, gyro);
    } catch (const InputError& err) {
      t.FailHere(err.what());
    }
  }
}

GyroConfig LoadGyro(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw InputError(fmt::format("{}: gyro file not found (expected a TOML gyro file, see scenarios/README.md)", path));
  }
  const auto doc = ParseTomlFile(path);
  const TomlReader root(*doc, path, "gyro");
  GyroConfig gyro;
  gyro.name = root.String("name", std::filesystem::path(path).stem().string());
  ReadNetwork(root, gyro.network);
  ReadSensors(root, gyro);
  ReadBias(root, gyro);
  ReadNoise(root, gyro);
  ReadAndApplyEffects(root, gyro);
  if (const auto cal = root.OptionalTable("calibration")) {
    gyro.calibration_uncertainty = cal->Positive("relative_uncertainty", 0.05);
    if (cal->Has("relative_uncertainty")) cal->InRange("relative_uncertainty", 0.0, range::kMaxCalibrationUncertainty);
    cal->Finish();
  }
  root.Finish();
  try {
    ThermalNetwork check(gyro.network);  // validates C > 0, paths to ambient, ...
  } catch (const InputError& err) {
    throw InputError(fmt::format("{}: {}", path, err.what()));
  }
  return gyro;
}

}  // namespace rlg::sim
