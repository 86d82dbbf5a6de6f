#include "sim/gyro_compare.h"

#include <cstdint>
#include <cstring>
#include <fmt/format.h>

namespace rlg::sim {
namespace {

// A tripwire, not a proof: on this platform (x86-64, libstdc++) the structs below have these
// sizes. A new field changes a size (unless it fits in padding), and then this fails to compile
// until the field is compared below, written by WriteGyroToml and read by LoadGyro.
#if defined(__x86_64__) && defined(__GLIBCXX__)
#define RLG_NEW_FIELD                                                                                      \
  "a field was added to a gyro struct: compare it in GyroDifference (sim/gyro_compare.cpp), write it in " \
  "WriteGyroToml (io/gyro_toml.cpp) and read it in LoadGyro, then update this size"
static_assert(sizeof(GyroConfig) == 520, RLG_NEW_FIELD);
static_assert(sizeof(NetworkSpec) == 120, RLG_NEW_FIELD);
static_assert(sizeof(NetworkSpec::Node) == 40, RLG_NEW_FIELD);
static_assert(sizeof(NetworkSpec::Link) == 16, RLG_NEW_FIELD);
static_assert(sizeof(NetworkSpec::Radiation) == 16, RLG_NEW_FIELD);
static_assert(sizeof(NetworkSpec::Source) == 96, RLG_NEW_FIELD);
static_assert(sizeof(NetworkSpec::Follower) == 16, RLG_NEW_FIELD);
static_assert(sizeof(SensorSpec) == 88, RLG_NEW_FIELD);
static_assert(sizeof(SensorNoiseParams) == 16, RLG_NEW_FIELD);
static_assert(sizeof(BiasParams) == 256, RLG_NEW_FIELD);
static_assert(sizeof(BiasParams::Gradient) == 16, RLG_NEW_FIELD);
static_assert(sizeof(BiasParams::Rate) == 16, RLG_NEW_FIELD);
static_assert(sizeof(BiasParams::Hysteresis) == 24, RLG_NEW_FIELD);
static_assert(sizeof(BiasParams::Play) == 32, RLG_NEW_FIELD);
static_assert(sizeof(GyroNoiseParams) == 56, RLG_NEW_FIELD);
static_assert(sizeof(EffectSpec) == 112, RLG_NEW_FIELD);
#undef RLG_NEW_FIELD
#endif

/// Collects the first difference; later comparisons are skipped once one is found.
class Differ {
 public:
  const std::string& first() const { return first_; }

  void Number(const std::string& field, double a, double b) {
    uint64_t ba = 0, bb = 0;
    std::memcpy(&ba, &a, sizeof a);
    std::memcpy(&bb, &b, sizeof b);
    if (ba != bb) Found(field, fmt::format("{} != {}", a, b));
  }
  void Integer(const std::string& field, long long a, long long b) {
    if (a != b) Found(field, fmt::format("{} != {}", a, b));
  }
  void Text(const std::string& field, const std::string& a, const std::string& b) {
    if (a != b) Found(field, fmt::format("\"{}\" != \"{}\"", a, b));
  }
  /// Sizes first, then each element pair through each(prefix, a_i, b_i).
  template <typename T, typename F>
  void List(const std::string& field, const std::vector<T>& a, const std::vector<T>& b, F each) {
    if (!first_.empty()) return;
    if (a.size() != b.size()) return Found(field, fmt::format("{} entries != {}", a.size(), b.size()));
    for (size_t i = 0; i < a.size() && first_.empty(); ++i) each(fmt::format("{}[{}]", field, i), a[i], b[i]);
  }

 private:
  void Found(const std::string& field, const std::string& what) {
    if (first_.empty()) first_ = field + ": " + what;
  }
  std::string first_;
};

/// Lists of two-ended entries (links, radiation, bias gradients): ends a and b and one number.
template <typename T>
void CompareEnds(Differ& d, const std::string& field, const std::vector<T>& a, const std::vector<T>& b,
                 double T::*value, const std::string& value_name) {
  d.List(field, a, b, [&](const std::string& f, const T& x, const T& y) {
    d.Integer(f + ".a", x.a, y.a);
    d.Integer(f + ".b", x.b, y.b);
    d.Number(f + "." + value_name, x.*value, y.*value);
  });
}

void CompareNetwork(Differ& d, const NetworkSpec& a, const NetworkSpec& b) {
  using N = NetworkSpec;
  d.List("network.nodes", a.nodes, b.nodes, [&](const std::string& f, const N::Node& x, const N::Node& y) {
    d.Text(f + ".name", x.name, y.name);
    d.Number(f + ".heat_capacity_J_per_K", x.heat_capacity_J_per_K, y.heat_capacity_J_per_K);
  });
  CompareEnds(d, "network.links", a.links, b.links, &N::Link::conductance_W_per_K, "conductance_W_per_K");
  CompareEnds(d, "network.radiation", a.radiation, b.radiation, &N::Radiation::emissivity_area_m2, "emissivity_area_m2");
  d.List("network.sources", a.sources, b.sources, [&](const std::string& f, const N::Source& x, const N::Source& y) {
    d.Text(f + ".name", x.name, y.name);
    d.List(f + ".shares", x.shares, y.shares,
           [&](const std::string& g, const std::pair<int, double>& s, const std::pair<int, double>& t) {
             d.Integer(g + ".node", s.first, t.first);
             d.Number(g + ".fraction", s.second, t.second);
           });
    d.Number(f + ".power_W", x.power_W, y.power_W);
    d.Integer(f + ".driven_by_data", x.driven_by_data, y.driven_by_data);
    d.Number(f + ".gain", x.gain, y.gain);
    d.Integer(f + ".drift_node", x.drift_node, y.drift_node);
    d.Number(f + ".drift_per_K", x.drift_per_K, y.drift_per_K);
    d.Number(f + ".drift_reference_C", x.drift_reference_C, y.drift_reference_C);
  });
  d.List("network.followers", a.followers, b.followers, [&](const std::string& f, const N::Follower& x, const N::Follower& y) {
    d.Integer(f + ".node", x.node, y.node);
    d.Number(f + ".time_constant_s", x.time_constant_s, y.time_constant_s);
  });
}

void CompareBias(Differ& d, const BiasParams& a, const BiasParams& b) {
  d.Integer("bias.node", a.node, b.node);
  d.Number("bias.reference_C", a.reference_C, b.reference_C);
  d.Number("bias.b0_dph", a.b0_dph, b.b0_dph);
  d.Number("bias.b1_dph_per_C", a.b1_dph_per_C, b.b1_dph_per_C);
  d.Number("bias.b2_dph_per_C2", a.b2_dph_per_C2, b.b2_dph_per_C2);
  d.Number("bias.langmuir_current_imbalance_mA", a.langmuir_current_imbalance_mA, b.langmuir_current_imbalance_mA);
  d.Number("bias.langmuir_dph_per_mA", a.langmuir_dph_per_mA, b.langmuir_dph_per_mA);
  d.Number("bias.langmuir_temperature_coeff_per_C", a.langmuir_temperature_coeff_per_C, b.langmuir_temperature_coeff_per_C);
  CompareEnds(d, "bias.langmuir_gradients", a.langmuir_gradients, b.langmuir_gradients, &BiasParams::Gradient::k_dph_per_C,
              "k_dph_per_C");
  d.Number("bias.path_length_m", a.path_length_m, b.path_length_m);
  d.Number("bias.cte_per_C", a.cte_per_C, b.cte_per_C);
  d.Number("bias.wavelength_m", a.wavelength_m, b.wavelength_m);
  d.Number("bias.plc_dph_per_wavelength", a.plc_dph_per_wavelength, b.plc_dph_per_wavelength);
  d.List("bias.rate_terms", a.rate_terms, b.rate_terms,
         [&](const std::string& f, const BiasParams::Rate& x, const BiasParams::Rate& y) {
           d.Integer(f + ".node", x.node, y.node);
           d.Number(f + ".k_dph_per_C_per_min", x.k_dph_per_C_per_min, y.k_dph_per_C_per_min);
         });
  CompareEnds(d, "bias.extra_gradients", a.extra_gradients, b.extra_gradients, &BiasParams::Gradient::k_dph_per_C,
              "k_dph_per_C");
  d.List("bias.hysteresis", a.hysteresis, b.hysteresis,
         [&](const std::string& f, const BiasParams::Hysteresis& x, const BiasParams::Hysteresis& y) {
           d.Integer(f + ".node", x.node, y.node);
           d.Number(f + ".k_heating_dph_per_C", x.k_heating_dph_per_C, y.k_heating_dph_per_C);
           d.Number(f + ".k_cooling_dph_per_C", x.k_cooling_dph_per_C, y.k_cooling_dph_per_C);
         });
  d.List("bias.play", a.play, b.play, [&](const std::string& f, const BiasParams::Play& x, const BiasParams::Play& y) {
    d.Integer(f + ".node", x.node, y.node);
    d.Number(f + ".k_dph_per_C", x.k_dph_per_C, y.k_dph_per_C);
    d.Number(f + ".width_C", x.width_C, y.width_C);
    d.Number(f + ".reference_C", x.reference_C, y.reference_C);
  });
  d.Integer("bias.mode_hops", a.mode_hops, b.mode_hops);
  d.Number("bias.mode_hop_step_dph", a.mode_hop_step_dph, b.mode_hop_step_dph);
  d.Number("bias.mode_hop_range_modes", a.mode_hop_range_modes, b.mode_hop_range_modes);
  d.Number("bias.mode_spacing_C", a.mode_spacing_C, b.mode_spacing_C);
  d.Number("bias.mode_hop_centre_C", a.mode_hop_centre_C, b.mode_hop_centre_C);
}

void CompareNoise(Differ& d, const GyroNoiseParams& a, const GyroNoiseParams& b) {
  d.Number("noise.arw_deg_per_sqrt_h", a.arw_deg_per_sqrt_h, b.arw_deg_per_sqrt_h);
  d.Number("noise.bias_instability_dph", a.bias_instability_dph, b.bias_instability_dph);
  d.Integer("noise.instability_model", static_cast<int>(a.instability_model), static_cast<int>(b.instability_model));
  d.Number("noise.gauss_markov_time_s", a.gauss_markov_time_s, b.gauss_markov_time_s);
  d.Number("noise.rrw_deg_per_h_per_sqrt_h", a.rrw_deg_per_h_per_sqrt_h, b.rrw_deg_per_h_per_sqrt_h);
  d.Number("noise.quantization_arcsec", a.quantization_arcsec, b.quantization_arcsec);
  d.Number("noise.turn_on_sigma_dph", a.turn_on_sigma_dph, b.turn_on_sigma_dph);
}

}  // namespace

std::string GyroDifference(const GyroConfig& a, const GyroConfig& b) {
  Differ d;
  d.Text("name", a.name, b.name);
  CompareNetwork(d, a.network, b.network);
  d.List("sensors", a.sensors, b.sensors, [&](const std::string& index, const SensorSpec& x, const SensorSpec& y) {
    const std::string f = fmt::format("{} ({})", index, x.channel);
    d.Text(f + ".channel", x.channel, y.channel);
    d.Integer(f + ".node", x.node, y.node);
    d.Number(f + ".noise_C", x.noise.sigma_C, y.noise.sigma_C);
    d.Number(f + ".resolution_C", x.noise.resolution_C, y.noise.resolution_C);
    d.Number(f + ".offset_C", x.offset_C, y.offset_C);
    d.List(f + ".lag_time_constants_s", x.lag_time_constants_s, y.lag_time_constants_s,
           [&](const std::string& i, double u, double v) { d.Number(i, u, v); });
  });
  CompareBias(d, a.bias, b.bias);
  CompareNoise(d, a.noise, b.noise);
  d.List("effects", a.effects, b.effects, [&](const std::string& index, const EffectSpec& x, const EffectSpec& y) {
    const std::string f = fmt::format("{} ({})", index, x.name);
    d.Text(f + ".name", x.name, y.name);
    d.Text(f + ".target", x.target, y.target);
    d.Integer(f + ".parameters count", static_cast<long long>(x.parameters.size()),
              static_cast<long long>(y.parameters.size()));
    auto ix = x.parameters.begin(), iy = y.parameters.begin();
    for (; ix != x.parameters.end() && iy != y.parameters.end(); ++ix, ++iy) {
      d.Text(f + ".parameter name", ix->first, iy->first);
      d.Number(f + "." + ix->first, ix->second, iy->second);
    }
  });
  d.Number("calibration_uncertainty", a.calibration_uncertainty, b.calibration_uncertainty);
  return d.first();
}

}  // namespace rlg::sim
