#include "io/gyro_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <set>
#include <toml++/toml.h>

#include "io/input_file.h"
#include "io/toml_reader.h"
#include "sim/effect_registry.h"
#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::io {

using sim::ApplyEffect;
using sim::BiasParams;
using sim::Effect;
using sim::EffectParameter;
using sim::EffectSpec;
using sim::FindEffect;
using sim::GyroConfig;
using sim::GyroNoiseParams;
using sim::NetworkSpec;
using sim::SensorSpec;
using sim::ThermalNetwork;
using sim::kAmbient;
namespace limits = sim::limits;

namespace {

// Physical ranges of gyro parameters: sim/limits.h.
namespace range = limits;

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
    src.gain = t.InRange("gain", 0.0, range::kMaxSourceGain, 1.0);
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

EffectSpec ReadEffect(const TomlReader& t) {
  EffectSpec e;
  e.name = t.String("name");
  e.target = t.String("target");
  // A parameter of the named effect must lie within what a file may give; anything else is
  // refused by ApplyEffect (an unknown effect or parameter).
  const Effect* effect = FindEffect(e.name);
  for (const auto& key : t.Keys()) {
    if (key == "name" || key == "target") continue;
    const EffectParameter* param = effect ? effect->FindParameter(key) : nullptr;
    e.parameters[key] = param ? t.InRange(key, param->file_lo, param->file_hi) : t.Number(key);
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
  if (!IsRegularFile(path)) {
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

}  // namespace rlg::io
