// The effect catalog as objects (sim/effect_registry.h): every effect is registered in catalog
// order with documented parameters, and, for bias effects, the term BiasModel adds is the
// effect's own (how diagnose searches them: tests/diagnosis/test_effect_search.cpp).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>

#include "sim/bias_model.h"
#include "sim/effect_registry.h"
#include "sim/effects/gradient.h"
#include "sim/effects/hysteresis.h"
#include "sim/effects/mode_hop.h"
#include "sim/effects/play.h"
#include "sim/effects/temperature_rate.h"
#include "sim/errors.h"
#include "sim/simulator.h"
#include "sim/stats.h"
#include "tests/sim/test_helpers.h"

namespace rlg::sim {
namespace {

using test::BiasAlong;
using test::NominalForBiasTerms;
using test::SmoothCycle;
using test::Track;

TEST(EffectRegistry, ListsTheElevenEffectsInSpecOrder) {
  const std::vector<std::string> spec = {"thermal.missing_mass", "thermal.missing_link", "thermal.power_drift",
                                         "thermal.radiation",    "sensor.lag",           "sensor.offset",
                                         "bias.temperature_rate", "bias.gradient",       "bias.hysteresis",
                                         "bias.play",            "bias.mode_hop"};
  std::vector<std::string> names;
  for (const auto& e : Effects()) names.push_back(e->name());
  EXPECT_EQ(names, spec);
  EXPECT_EQ(EffectNames(), spec);
  for (const auto& e : Effects()) EXPECT_EQ(FindEffect(e->name()), e.get());
}

TEST(EffectRegistry, KindFollowsTheNamesPrefix) {
  for (const auto& e : Effects()) {
    const std::string prefix = e->name().substr(0, e->name().find('.'));
    const EffectKind expected = prefix == "thermal" ? EffectKind::kThermal
                                : prefix == "sensor" ? EffectKind::kSensor
                                                     : EffectKind::kBias;
    EXPECT_EQ(e->kind(), expected) << e->name();
  }
}

TEST(EffectRegistry, UnknownNameIsRefusedWithTheCatalog) {
  EXPECT_EQ(FindEffect("none"), nullptr);
  try {
    RequireEffect("bias.wobble");
    ADD_FAILURE() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown effect 'bias.wobble'; the catalog (scenarios/README.md, Effects) "
                                         "has: thermal.missing_mass, "),
              std::string::npos)
        << e.what();
  }
}

TEST(EffectRegistry, EveryParameterHasAUnitAPlausibleRangeAndItsSource) {
  for (const auto& e : Effects()) {
    ASSERT_FALSE(e->parameters().empty()) << e->name();
    for (const auto& p : e->parameters()) {
      SCOPED_TRACE(e->name() + " " + p.name);
      EXPECT_FALSE(p.unit.empty());
      EXPECT_LT(p.lo, p.hi);
      if (p.positive) {
        EXPECT_GE(p.lo, 0.0);
      }
      EXPECT_TRUE(p.source.rfind("[src] ", 0) == 0 || p.source.rfind("[est] ", 0) == 0) << p.source;
      // What a file may give is wider than what is plausible: a fit may wander outside the
      // plausible range (and is then reported as implausible), but never outside the file's.
      EXPECT_LE(p.file_lo, p.lo);
      EXPECT_GE(p.file_hi, p.hi);
      EXPECT_EQ(e->FindParameter(p.name), &p);
      // A default stands in for a file's value (0 may mean "derived", e.g. a mode spacing;
      // NaN a form, e.g. a mode hop's centred power-on without a centre).
      if (p.default_value && !std::isnan(*p.default_value)) {
        EXPECT_GE(*p.default_value, p.file_lo);
        EXPECT_LE(*p.default_value, p.file_hi);
      }
      // A reference of the form (a drift's reference temperature) has its default.
      if (p.reference) {
        EXPECT_TRUE(p.default_value.has_value());
      }
    }
  }
}

TEST(EffectRegistry, SensorEffectsKeepTheirChannelOthersNameNodes) {
  const GyroConfig g = test::NoiselessDefaultGyro();
  EXPECT_EQ(RequireEffect("sensor.offset").CanonicalTarget(g, "T1"), "T1");
  EXPECT_EQ(RequireEffect("bias.temperature_rate").CanonicalTarget(g, "T1"), "block");
  EXPECT_EQ(RequireEffect("bias.gradient").CanonicalTarget(g, "T3-T2"), "anode-cabinet");
  EXPECT_EQ(RequireEffect("thermal.missing_link").CanonicalTarget(g, "cathode-ambient"), "cathode-ambient");
}

TEST(BiasPhysics, TheSimulatorAddsEachBiasEffectsOwnTerm) {
  const GyroConfig nominal = NominalForBiasTerms();
  const Track x = SmoothCycle(static_cast<int>(nominal.network.nodes.size()));
  const std::vector<double> base = BiasAlong(nominal.bias, x);
  const int block = nominal.bias.node;
  // The term each effect's own function gives, along the track: expected[k].
  struct Case {
    std::string effect, target;
    std::function<std::vector<double>(const ParameterMap&)> term;
    ParameterMap given = {};  ///< parameters other than kTypical's
  };
  // Each effect at a typical size (the diagnosis's start values, diagnosis/catalog/).
  const std::map<std::string, ParameterMap> kTypical = {
      {"bias.temperature_rate", {{"k_dph_per_C_per_min", 0.05}}},
      {"bias.gradient", {{"k_dph_per_C", 0.05}}},
      {"bias.hysteresis", {{"k_heating_dph_per_C", 0.01}, {"k_cooling_dph_per_C", 0.0}}},
      {"bias.play", {{"k_dph_per_C", 0.01}, {"width_C", 2.0}, {"reference_C", 20.0}}},
      {"bias.mode_hop", {{"step_dph", 0.05}, {"range_modes", 0.6}, {"mode_spacing_C", 30.0}, {"centre_C", 20.0}}}};
  // A mode hop powered on centred (no centre_C), and locked by an absolute centre 7.5 °C above
  // the block's first temperature (0.25 of its 30 °C spacing, so the travel starts off
  // centre), with hysteresis and without (range 0.5).
  const auto mode_hop = [&](const ParameterMap& p) {
    // The steps, and the path-length control's travel, which resets with each hop.
    std::vector<double> v;
    const double spacing = p.at("mode_spacing_C"), plc = nominal.bias.plc_dph_per_wavelength;
    const PlcLock on = PowerOn(x.T(block, 0), p.at("centre_C"), spacing);
    const double lock = on.T_lock_C;
    int mode = on.mode, never = 0;
    for (Eigen::Index k = 0; k < x.T.cols(); ++k) {
      const double u = PathLengthTravel(x.T(block, k), lock, spacing, p.at("range_modes"), mode);
      const double u_unlimited =
          PathLengthTravel(x.T(block, k), x.T(block, 0), spacing, std::numeric_limits<double>::infinity(), never);
      v.push_back(ModeHopEffect::Bias_dph(p.at("step_dph"), mode) + plc * (u - u_unlimited));
    }
    return v;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Case> cases = {
      {"bias.temperature_rate", "T4",
       [&](const ParameterMap& p) {
         std::vector<double> v;
         for (Eigen::Index k = 0; k < x.T.cols(); ++k)
           v.push_back(TemperatureRateEffect::Bias_dph(p.at("k_dph_per_C_per_min"), x.Tdot(1, k)));  // T4: cathode
         return v;
       }},
      {"bias.gradient", "anode-cabinet",
       [&](const ParameterMap& p) {
         std::vector<double> v;
         for (Eigen::Index k = 0; k < x.T.cols(); ++k) v.push_back(GradientEffect::Bias_dph(p.at("k_dph_per_C"), x.T(0, k), x.T(3, k)));
         return v;
       }},
      {"bias.hysteresis", "block",
       [&](const ParameterMap& p) {
         std::vector<double> v;
         double last = x.T(block, 0), accumulated = 0.0;
         for (Eigen::Index k = 0; k < x.T.cols(); ++k)
           v.push_back(HysteresisEffect::Bias_dph(p.at("k_heating_dph_per_C"), p.at("k_cooling_dph_per_C"), x.T(block, k),
                                                  last, accumulated));
         return v;
       }},
      {"bias.play", "block",
       [&](const ParameterMap& p) {
         std::vector<double> v;
         double play = x.T(block, 0);
         for (Eigen::Index k = 0; k < x.T.cols(); ++k)
           v.push_back(PlayEffect::Bias_dph(p.at("k_dph_per_C"), p.at("width_C"), p.at("reference_C"), x.T(block, k), play));
         return v;
       }},
      {"bias.mode_hop", "block", mode_hop, {{"centre_C", nan}}},
      {"bias.mode_hop", "block", mode_hop, {{"centre_C", 27.5}}},
      {"bias.mode_hop", "block", mode_hop, {{"centre_C", 27.5}, {"range_modes", 0.5}}},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.effect);
    ParameterMap p = kTypical.at(c.effect);
    for (const auto& [key, v] : c.given) p[key] = v;
    GyroConfig with = nominal;
    ApplyEffect({c.effect, c.target, p}, with);
    const std::vector<double> b = BiasAlong(with.bias, x), expected = c.term(p);
    double largest = 0.0;
    for (size_t k = 0; k < b.size(); ++k) {
      // The same term added to a bias of ~1 °/h: the difference rounds to within a few 1e-16
      // °/h (6e-16 measured); 1e-12 is margin. (The mode hop's travel term rounds alike.)
      EXPECT_NEAR(b[k] - base[k], expected[k], 1e-12) << "sample " << k;
      largest = std::max(largest, std::abs(expected[k]));
    }
    EXPECT_GT(largest, 0.01);  // the track shows the term (hops, heating, gradients, rates)
  }
}

TEST(BiasPhysics, ABlockOfSamplesGivesTheBiasesOfOneAtATimeToTheBit) {
  // The simulator evaluates the bias a block at a time, term by term (BiasModel::Evaluate over
  // n samples); that must be the per-sample evaluation exactly, with every term and its history
  // (PLC resets, hysteresis, play) on or off, across the block's inner chunks of 256 samples.
  BiasParams p;
  p.node = 1;
  p.reference_C = 21.5;
  p.b0_dph = 0.7;
  p.b1_dph_per_C = 0.013;
  p.b2_dph_per_C2 = -3e-4;
  p.langmuir_current_imbalance_mA = 0.02;
  p.langmuir_dph_per_mA = 0.0066;
  p.langmuir_temperature_coeff_per_C = 0.004;
  p.langmuir_gradients = {{0, 1, 0.4}, {2, 1, -0.3}};
  p.plc_dph_per_wavelength = 0.02;
  p.mode_spacing_C = 0.7;
  p.rate_terms = {{0, 0.05}, {2, -0.02}};
  p.extra_gradients = {{0, 2, 0.01}};
  p.hysteresis = {{1, 0.002, 0.0011}, {2, 0.001, 0.003}};
  p.play = {{0, 0.02, 1.3, 20.0}};
  const size_t n = 700, stride = 3;  // two whole chunks and part of a third
  std::vector<double> T(n * stride), Tdot(n * stride);
  for (size_t j = 0; j < n; ++j) {
    for (size_t i = 0; i < stride; ++i) {
      // Up and down by a few modes, each node on its own phase: hops both ways, both branches of
      // the hysteresis and of the play.
      const double w = 0.011 * (1.0 + 0.3 * static_cast<double>(i));
      T[j * stride + i] = 25.0 + 4.0 * std::sin(w * static_cast<double>(j) + static_cast<double>(i));
      Tdot[j * stride + i] = 4.0 * w * std::cos(w * static_cast<double>(j) + static_cast<double>(i));
    }
  }
  // A NaN reading late in the run: both paths carry it the same way (no branch on it).
  T[650 * stride + 2] = std::numeric_limits<double>::quiet_NaN();
  for (int hops : {0, 1, 2}) {  // none; power on centred on a mode; on the mode nearest a centre
    p.mode_hops = hops > 0;
    p.mode_hop_step_dph = hops > 0 ? 0.03 : 0.0;
    p.mode_hop_centre_C = hops == 2 ? 23.9 : std::numeric_limits<double>::quiet_NaN();
    const BiasModel model(p);
    const Eigen::Map<const Eigen::VectorXd> T0(T.data(), stride);
    BiasModel::State one = model.Start(T0), block = model.Start(T0);
    std::vector<double> expected(n), got(n);
    for (size_t j = 0; j < n; ++j) {
      expected[j] = model.Evaluate(Eigen::Map<const Eigen::VectorXd>(T.data() + j * stride, stride),
                                   Eigen::Map<const Eigen::VectorXd>(Tdot.data() + j * stride, stride), one);
    }
    model.Evaluate(T.data(), Tdot.data(), stride, n, got.data(), block);
    for (size_t j = 0; j < n; ++j) {  // bits, not ==: -0 and NaN count
      ASSERT_EQ(std::memcmp(&got[j], &expected[j], sizeof(double)), 0)
          << "sample " << j << ": " << got[j] << " against " << expected[j] << ", mode hops " << hops;
    }
    const auto same_bits = [](const std::vector<double>& a, const std::vector<double>& b) {
      return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(double)) == 0;
    };
    EXPECT_EQ(block.mode, one.mode);
    EXPECT_TRUE(same_bits(block.hysteresis_dph, one.hysteresis_dph));
    EXPECT_TRUE(same_bits(block.play_C, one.play_C));
    if (hops > 0) {
      EXPECT_NE(one.mode, 0);  // the track crossed modes: the stateful path was taken
    }
  }
}

TEST(BiasPhysics, ResetTravelJumpsAllItsModesAtOnceAsOneAtATimeWould) {
  // The reference: one mode per loop, as the control jumps. ResetTravel counts the jumps at once;
  // mode and travel must be those of the loop to the bit, on both sides of both bounds.
  const auto one_at_a_time = [](double lock_travel, double range, int& mode) {
    double u = lock_travel - mode;
    while (u > range) ++mode, u -= 1.0;
    while (u < -range) --mode, u += 1.0;
    return u;
  };
  uint64_t z = 12345;
  const auto uniform = [&z] {  // SplitMix64 to [0, 1): a test's own stream, no library needed
    z += 0x9E3779B97F4A7C15ULL;
    uint64_t x = z;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ULL;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBULL;
    return static_cast<double>((x ^ (x >> 31)) >> 11) * 0x1p-53;
  };
  int checked = 0;
  for (const double range : {0.5, 0.6, 1.0, 2.75, 3.0}) {
    for (const double scale : {0.5, 3.0, 1e3, 1e6}) {
      const int draws = scale < 1e6 ? 2000 : 20;  // the reference loops |u| times a draw
      for (int i = 0; i < draws; ++i) {
        // Modes near 0, and every third draw far from it (up to 1e8 either way).
        const double mode_scale = i % 3 == 0 ? 2e8 : 20.0;
        int mode = static_cast<int>(std::lround((uniform() - 0.5) * mode_scale)), expected_mode = mode;
        double lock_travel = mode + (2.0 * uniform() - 1.0) * scale;
        if (i % 7 == 0) lock_travel = std::round(lock_travel) + range;  // on a bound: no jump there
        if (i % 11 == 0) lock_travel = std::round(lock_travel) - range;
        const double expected = one_at_a_time(lock_travel, range, expected_mode);
        const double got = ResetTravel(lock_travel, range, mode);
        ASSERT_EQ(std::memcmp(&got, &expected, sizeof got), 0) << lock_travel << " range " << range;
        ASSERT_EQ(mode, expected_mode) << lock_travel << " range " << range;
        ++checked;
      }
    }
  }
  EXPECT_EQ(checked, 5 * (3 * 2000 + 20));
}

TEST(BiasPhysics, NoControlTravelsToAnInfiniteTemperature) {
  // One mode per loop never ended at an infinite or absurd bias-node temperature (u - 1 == u):
  // now the travel is NaN, its mode unchanged, and the simulator refuses the run.
  constexpr double kInf = std::numeric_limits<double>::infinity();
  for (const double travel : {kInf, -kInf, 1e300, -2e9, 1.5e9}) {
    int mode = 3;
    EXPECT_TRUE(std::isnan(ResetTravel(travel, 0.6, mode))) << travel;
    EXPECT_EQ(mode, 3) << travel;
  }
  // At the bound: 1e9 modes in one sample are taken, the next double above is not.
  int mode = 0;
  EXPECT_EQ(ResetTravel(1e9, 0.6, mode), 0.0);
  EXPECT_EQ(mode, 1'000'000'000);
  mode = 0;
  EXPECT_TRUE(std::isnan(ResetTravel(std::nextafter(1e9, kInf), 0.6, mode)));
  EXPECT_EQ(mode, 0);
  // Nor a mode index beyond 1e9 reached in steps below it, where an int would overflow.
  mode = 0;
  EXPECT_FALSE(std::isnan(ResetTravel(9e8, 0.6, mode)));
  EXPECT_EQ(mode, 900'000'000);
  EXPECT_TRUE(std::isnan(ResetTravel(1.8e9, 0.6, mode)));
  EXPECT_EQ(mode, 900'000'000);
  mode = -900'000'000;
  EXPECT_TRUE(std::isnan(ResetTravel(-1.8e9, 0.6, mode)));
  EXPECT_EQ(mode, -900'000'000);
  mode = 3;
  EXPECT_TRUE(std::isnan(ResetTravel(std::numeric_limits<double>::quiet_NaN(), 0.6, mode)));  // NaN passes through, as before
  EXPECT_EQ(mode, 3);
  EXPECT_EQ(ResetTravel(1e300, kInf, mode), 1e300 - 3.0);  // a control that never resets
  // Through the bias model: a mode-hopping gyro whose bias node reads +inf gives NaN, at once.
  BiasParams p;
  p.node = 0;
  p.mode_spacing_C = 0.7;
  p.mode_hops = true;
  p.mode_hop_step_dph = 0.03;
  p.mode_hop_range_modes = 0.6;
  for (const double centre : {std::numeric_limits<double>::quiet_NaN(), 20.0}) {
    p.mode_hop_centre_C = centre;
    const BiasModel model(p);
    Eigen::VectorXd T(1), Tdot = Eigen::VectorXd::Zero(1);
    T << 20.0;
    BiasModel::State state = model.Start(T);
    T << kInf;
    EXPECT_TRUE(std::isnan(model.Evaluate(T, Tdot, state)));
    EXPECT_TRUE(std::isnan(model.Evaluate(T, Tdot, state)));  // and again: the state is still usable
    T << 20.0;
    EXPECT_TRUE(std::isfinite(model.Evaluate(T, Tdot, state)));
    if (std::isnan(centre)) continue;  // centred power-on locks where it starts: no travel
    // Powered on 1e300 °C from its centre: the first travel is NaN, no undefined int conversion.
    T << 1e300;
    BiasModel::State absurd = model.Start(T);
    EXPECT_EQ(absurd.mode, 0);
    EXPECT_TRUE(std::isnan(model.Evaluate(T, Tdot, absurd)));
  }
}

TEST(BiasPhysics, ModeHopsWithoutHysteresisAreAStaircaseOfAbsoluteTemperature) {
  // Closed form: at range 0.5 with a centre T_c, the control holds the mode nearest its centre
  // at every instant, m = round((T_b - T_c) / dT_mode), whatever the path and the power-on
  // temperature; so the bias (step 1, nothing else) is that staircase, on the way up and down.
  BiasParams p;
  p.node = 0;
  p.mode_hops = true;
  p.mode_hop_step_dph = 1.0;
  p.mode_hop_range_modes = 0.5;
  p.mode_spacing_C = 10.0;
  p.mode_hop_centre_C = 3.0;
  const BiasModel model(p);
  // Two runs powered on at 17.3 and 24.1 °C, each up to 52.7, down to 8.1 and back to 30.9 in
  // 0.013 °C steps (no sample on an edge 3 + 10 (k + 1/2)).
  for (double start : {17.3, 24.1}) {
    std::vector<double> track;
    for (double T = start; T < 52.7; T += 0.013) track.push_back(T);
    for (double T = 52.7; T > 8.1; T -= 0.013) track.push_back(T);
    for (double T = 8.1; T < 30.9; T += 0.013) track.push_back(T);
    Eigen::VectorXd T(1), Tdot = Eigen::VectorXd::Zero(1);
    T[0] = track.front();
    BiasModel::State state = model.Start(T);
    int steps_seen = 0;
    for (size_t k = 0; k < track.size(); ++k) {
      T[0] = track[k];
      const double b = model.Evaluate(T, Tdot, state);
      ASSERT_EQ(b, std::round((track[k] - 3.0) / 10.0)) << "start " << start << ", T = " << track[k];
      steps_seen += k > 0 && std::round((track[k] - 3.0) / 10.0) != std::round((track[k - 1] - 3.0) / 10.0);
    }
    EXPECT_GE(steps_seen, 9);  // edges at 8, 18 ... 48 °C: 3-4 up, 4 down, 2 up again
  }
  // Without a centre the same control powers on centred: m = 0 at power-on, whatever T_b.
  p.mode_hop_centre_C = std::numeric_limits<double>::quiet_NaN();
  Eigen::VectorXd T(1), Tdot = Eigen::VectorXd::Zero(1);
  T[0] = 24.1;
  BiasModel::State state = BiasModel(p).Start(T);
  EXPECT_EQ(BiasModel(p).Evaluate(T, Tdot, state), 0.0);
}

TEST(BiasPhysics, TheBaselineIsItsRegressorsTimesTheFilesCoefficientsUpToARunConstant) {
  // diagnose fits the baseline bias as c_run + beta . x; with the gyro file's beta
  // (BaselineCoefficients) that linear model must be the simulator's bias, up to a constant.
  const GyroConfig g = test::NoiselessDefaultGyro();
  ASSERT_FALSE(g.bias.mode_hops);  // within one mode the PLC is linear in T_b
  const Track x = SmoothCycle(static_cast<int>(g.network.nodes.size()));
  const std::vector<double> b = BiasAlong(g.bias, x);
  const std::vector<double> beta = BaselineCoefficients(g.bias);
  ASSERT_EQ(static_cast<int>(beta.size()), NumBaselineRegressors(g.bias));
  Eigen::RowVectorXd row(NumBaselineRegressors(g.bias));
  std::vector<double> linear;
  for (Eigen::Index k = 0; k < x.T.cols(); ++k) {
    BaselineRegressors(g.bias, x.T.col(k), row);
    double v = 0.0;
    for (size_t j = 0; j < beta.size(); ++j) v += beta[j] * row[static_cast<Eigen::Index>(j)];
    linear.push_back(v);
  }
  double largest = 0.0;
  for (size_t k = 0; k < b.size(); ++k) {
    // The bilinear Langmuir term expanded into two products rounds differently: terms of a few
    // °/h over the cycle, each rounded at 1e-16 relative (2.7e-15 °/h measured); 1e-11 is margin.
    EXPECT_NEAR(b[k] - b[0], linear[k] - linear[0], 1e-11) << "sample " << k;
    largest = std::max(largest, std::abs(b[k] - b[0]));
  }
  EXPECT_GT(largest, 1.0);  // the cycle moves the baseline bias by more than 1 °/h
}

TEST(BiasPhysics, IntrinsicRegressorsAreTheTermAtUnitCoefficientsToTheBit) {
  for (double dT : {-37.25, -1e-3, 0.0, 0.1, 2.5, 41.0}) {
    EXPECT_EQ(IntrinsicBias_dph(0.0, 1.0, 0.0, dT), dT);
    EXPECT_EQ(IntrinsicBias_dph(0.0, 0.0, 1.0, dT), dT * dT);
  }
}

}  // namespace
}  // namespace rlg::sim
