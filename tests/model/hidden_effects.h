#pragma once
// Hidden-effect experiments for the diagnosis tests: simulate the diagnosis suite from the
// default gyro with one catalog effect switched on, at a strength drawn from a seeded
// generator, 3-6x the noise at 100 s averaging. This file is the truth side: the diagnosis
// code never sees it.

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/uniform_real_distribution.hpp>
#include <gtest/gtest.h>
#include <cmath>
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "model/diagnose.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace rlg::test {

struct HiddenCase {
  std::string effect;  ///< "none" for no effect
  std::string target;
  std::map<std::string, double> parameters;
  std::string checked;  ///< the parameter the test compares
  double strength = 0.0;  ///< effect RMS / noise RMS at 100 s
};

/// Effect, targets to draw from, starting parameters (their direction) and the parameter to
/// check. Targets are those the data can identify (see README "What diagnosis can tell apart").
struct CatalogEntry {
  std::string effect;
  std::vector<std::string> targets;
  std::map<std::string, double> start;
  std::string checked;
  std::string scaled;  ///< the parameter scaled to reach the strength
};

inline const std::vector<CatalogEntry>& HiddenCatalog() {
  static const std::vector<CatalogEntry> c = {
      {"thermal.missing_mass", {"block-cabinet", "anode-cabinet"}, {{"heat_capacity_J_per_K", 200.0}, {"conductance_W_per_K", 0.02}}, "conductance_W_per_K", "conductance_W_per_K"},
      {"thermal.missing_link", {"anode-cathode", "cathode-cabinet", "cathode-ambient"}, {{"conductance_W_per_K", 0.005}}, "conductance_W_per_K", "conductance_W_per_K"},
      {"thermal.power_drift", {"cathode", "anode"}, {{"g_per_C", 0.001}, {"reference_C", 20.0}}, "g_per_C", "g_per_C"},
      {"thermal.radiation", {"block-ambient", "anode-ambient", "cathode-ambient"}, {{"emissivity_area_m2", 0.001}}, "emissivity_area_m2", "emissivity_area_m2"},
      {"sensor.lag", {"T1", "T2", "T3", "T4"}, {{"time_constant_s", 20.0}}, "time_constant_s", "time_constant_s"},
      {"sensor.offset", {"T1", "T2", "T3", "T4"}, {{"offset_C", 0.001}}, "offset_C", "offset_C"},
      {"bias.temperature_rate", {"T1", "T4"}, {{"k_dph_per_C_per_min", 0.02}}, "k_dph_per_C_per_min", "k_dph_per_C_per_min"},
      {"bias.gradient", {"anode-cabinet", "cathode-cabinet", "block-cathode"}, {{"k_dph_per_C", 0.01}}, "k_dph_per_C", "k_dph_per_C"},
      {"bias.hysteresis", {"block"}, {{"k_heating_dph_per_C", 0.002}, {"k_cooling_dph_per_C", 0.0}}, "k_heating_dph_per_C", "k_heating_dph_per_C"},
      {"bias.mode_hop", {"block"}, {{"step_dph", 0.02}}, "step_dph", "step_dph"},
  };
  return c;
}

inline sim::Scenario DiagnosisScenario() {
  return sim::LoadScenario(std::string(RLG_SOURCE_DIR) + "/scenarios/diagnosis-suite.toml");
}

inline sim::GyroConfig Noiseless(sim::GyroConfig g) {
  g.noise = sim::GyroNoiseParams{};
  for (auto& s : g.sensors) s.noise = sim::SensorNoiseParams{};
  return g;
}

/// RMS over runs of 100 s means of a - b in `column` (the largest over T channels for "T*").
inline double EffectRms(const sim::Trace& a, const sim::Trace& b, bool bias) {
  double worst = 0.0;
  const std::vector<std::string> cols = bias ? std::vector<std::string>{"bias_dph"}
                                             : std::vector<std::string>{"T1", "T2", "T3", "T4"};
  for (const auto& col : cols) {
    double ss = 0.0;
    int n = 0;
    for (size_t r = 0; r < a.runs.size(); ++r) {
      const auto& x = a.runs[r].Column(col);
      const auto& y = b.runs[r].Column(col);
      for (size_t k = 0; k + 100 <= x.size(); k += 100) {
        double m = 0.0;
        for (size_t i = k; i < k + 100; ++i) m += x[i] - y[i];
        m /= 100.0;
        ss += m * m;
        ++n;
      }
    }
    worst = std::max(worst, std::sqrt(ss / n));
  }
  return worst;
}

/// Noise RMS at 100 s of the default gyro: gyro (ARW and the flicker floor) or sensor (white
/// noise and resolution), from its own parameters.
inline double NoiseRms100(const sim::GyroConfig& g, bool bias) {
  if (bias) {
    const double white = 60.0 * g.noise.arw_deg_per_sqrt_h / std::sqrt(100.0);
    return std::hypot(white, 0.664 * g.noise.bias_instability_dph);
  }
  const auto& s = g.sensors.front().noise;
  return std::sqrt((s.sigma_C * s.sigma_C + s.resolution_C * s.resolution_C / 12.0) / 100.0);
}

/// Draws a case for `effect` from `seed` and returns the simulated data.
inline sim::Trace MakeHiddenCase(const std::string& effect, uint64_t seed, HiddenCase* truth) {
  boost::random::mt19937_64 rng(seed);
  boost::random::uniform_real_distribution<double> u(0.0, 1.0);
  sim::Scenario sc = DiagnosisScenario();
  truth->effect = effect;
  if (effect == "none") return sim::SimulateScenario(sc, seed);
  const CatalogEntry* entry = nullptr;
  for (const auto& e : HiddenCatalog())
    if (e.effect == effect) entry = &e;
  truth->target = entry->targets[static_cast<size_t>(u(rng) * entry->targets.size()) % entry->targets.size()];
  truth->checked = entry->checked;
  truth->strength = 3.0 + 3.0 * u(rng);
  const bool bias = effect.rfind("bias.", 0) == 0;
  const sim::GyroConfig clean = Noiseless(sc.gyro);
  sim::Scenario clean_sc = sc;
  clean_sc.gyro = clean;
  const sim::Trace without = sim::SimulateScenario(clean_sc, 1);
  std::map<std::string, double> p = entry->start;
  const double goal = truth->strength * NoiseRms100(sc.gyro, bias);
  for (int iteration = 0; iteration < 3; ++iteration) {  // effects are nearly linear in it
    sim::Scenario with = clean_sc;
    sim::ApplyEffect({effect, truth->target, p}, with.gyro);
    const double rms = EffectRms(sim::SimulateScenario(with, 1), without, bias);
    p[entry->scaled] *= goal / rms;
  }
  truth->parameters = p;
  sim::ApplyEffect({effect, truth->target, p}, sc.gyro);
  return sim::SimulateScenario(sc, seed);
}

/// Targets the data cannot tell apart count as the same (README, "What diagnosis can tell
/// apart"): a gradient is known up to the Langmuir gradients already in the bias model, and a
/// power drift acts on a heat source whichever of its nodes drives it.
inline bool SameTarget(const sim::GyroConfig& g, const std::string& effect, const std::string& a, const std::string& b) {
  const std::string ca = model::CanonicalTarget(g, effect, a), cb = model::CanonicalTarget(g, effect, b);
  if (ca == cb) return true;
  auto merge = [&](std::string name) {
    if (effect == "bias.gradient") {
      for (const auto& gr : g.bias.langmuir_gradients) {
        const std::string x = g.network.nodes[gr.a].name, y = g.network.nodes[gr.b].name;
        if (name == y) name = x;
      }
    }
    return name;
  };
  if (effect == "bias.gradient") {
    auto split = [&](const std::string& t) {
      const auto d = t.find('-');
      std::string x = merge(t.substr(0, d)), y = merge(t.substr(d + 1));
      if (y < x) std::swap(x, y);
      return x + "-" + y;
    };
    return split(ca) == split(cb);
  }
  if (effect == "thermal.power_drift") {
    for (const auto& src : g.network.sources) {
      bool has_a = false, has_b = false;
      for (const auto& sh : src.shares) {
        has_a = has_a || g.network.nodes[sh.first].name == ca;
        has_b = has_b || g.network.nodes[sh.first].name == cb;
      }
      if (has_a && has_b) return true;
    }
  }
  return false;
}

/// The nominal gyro as diagnose gets it: the simulator's own gyro is the truth here, so its
/// parameters are known far better than a build tolerance.
inline sim::GyroConfig NominalForDiagnosis() {
  sim::GyroConfig g = DiagnosisScenario().gyro;
  g.calibration_uncertainty = 0.005;
  return g;
}

/// A clearly visible hidden effect and the parameter to compare.
struct ClearCase {
  std::string effect, target, checked;
  std::map<std::string, double> parameters;
};

/// gtest prints the case by name instead of its bytes.
inline void PrintTo(const ClearCase& c, std::ostream* os) { *os << c.effect << " on " << c.target; }

/// Simulates the diagnosis suite with `c` on and diagnoses it against the nominal gyro:
/// the right cause and target, the parameter within 20 % (the bound), a held-out gain.
inline void ExpectClearEffectFound(const ClearCase& c) {
  sim::Scenario sc = DiagnosisScenario();
  sim::ApplyEffect({c.effect, c.target, c.parameters}, sc.gyro);
  const model::Diagnosis d =
      model::Diagnose(sim::SimulateScenario(sc, sc.seed), DiagnosisScenario().gyro, model::DiagnoseOptions{});
  ASSERT_FALSE(d.steps.empty()) << "nothing accepted";
  const model::Candidate& got = d.steps.front().accepted;
  ASSERT_EQ(got.cause, c.effect);  // the parameters below exist only for the right cause
  EXPECT_TRUE(SameTarget(DiagnosisScenario().gyro, c.effect, got.target, c.target)) << got.target;
  EXPECT_NEAR(got.parameters.at(c.checked), c.parameters.at(c.checked), 0.2 * std::abs(c.parameters.at(c.checked)));
  EXPECT_GT(got.heldout_rms_ratio, 1.2);
}

inline std::string TestName(std::string effect) {
  for (auto& ch : effect)
    if (ch == '.') ch = '_';
  return effect;
}

}  // namespace rlg::test
