// The effect catalog as objects (sim/effect_registry.h): every effect is registered in catalog
// order with documented parameters, changes the simulation at its start values, and, for bias
// effects, is one physics: the term BiasModel adds is the effect's own, and the regressor
// `diagnose` fits is that term at unit coefficient.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

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

const std::vector<std::string> kChannels = {"T1", "T2", "T3", "T4"};

TargetSpace SpaceOf(const GyroConfig& g) {
  return {g, static_cast<int>(g.network.nodes.size()), kChannels};
}

/// Largest absolute difference over every column of two runs of the same shape.
double LargestDifference(const Run& a, const Run& b) {
  double d = 0.0;
  for (size_t c = 0; c < a.columns.size(); ++c)
    for (size_t k = 0; k < a.size(); ++k) d = std::max(d, std::abs(a.columns[c][k] - b.columns[c][k]));
  return d;
}

/// Smooth node temperatures (°C) and their exact rates (°C/s), nodes x samples: each node rises
/// by 40 a_i °C and falls back, with its own amplitude and delay, so that gradients, heating and
/// cooling, rates and a 40 °C block excursion all occur.
struct Track {
  Eigen::MatrixXd T, Tdot;
};
Track SmoothCycle(int nodes) {
  const int samples = 2000;
  const double period_s = 8000.0, dt = period_s / samples;
  Track x{Eigen::MatrixXd(nodes, samples), Eigen::MatrixXd(nodes, samples)};
  for (int i = 0; i < nodes; ++i) {
    const double amplitude = 40.0 * (1.0 + 0.15 * i), delay_s = 150.0 * i, w = 2.0 * M_PI / period_s;
    for (int k = 0; k < samples; ++k) {
      const double t = k * dt - delay_s;
      x.T(i, k) = 20.0 + amplitude * (1.0 - std::cos(w * t)) / 2.0;
      x.Tdot(i, k) = amplitude * w * std::sin(w * t) / 2.0;
    }
  }
  return x;
}

/// The noiseless default gyro with the mode spacing a mode hop's start applies: that start
/// sets the spacing the path-length control's travel term uses too, and with the nominal at the
/// same spacing a bias difference is the effect's term alone.
GyroConfig NominalForBiasTerms() {
  GyroConfig g = test::NoiselessDefaultGyro();
  g.bias.mode_spacing_C = RequireEffect("bias.mode_hop").Start().at("mode_spacing_C");
  return g;
}

/// Bias of `params` along a track, sample by sample as the simulator evaluates it.
std::vector<double> BiasAlong(const BiasParams& params, const Track& x) {
  const BiasModel model(params);
  BiasModel::State state = model.Start(x.T.col(0));
  std::vector<double> b;
  for (Eigen::Index k = 0; k < x.T.cols(); ++k) b.push_back(model.Evaluate(x.T.col(k), x.Tdot.col(k), state));
  return b;
}

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

TEST(EffectRegistry, TheBiasEffectsComputedFromTracksAreTheRateTheGradientAndHysteresis) {
  // What diagnose tries on measured channels without a thermal network: not a mode hop, whose
  // term needs the cavity's length and expansion from a gyro file.
  std::vector<std::string> from_tracks;
  for (const auto& e : Effects())
    if (e->ComputedFromTracks()) from_tracks.push_back(e->name());
  EXPECT_EQ(from_tracks, (std::vector<std::string>{"bias.temperature_rate", "bias.gradient", "bias.hysteresis"}));
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
    }
  }
}

TEST(EffectRegistry, StartsLieInTheirPlausibleRangeAndDefaultsInWhatAFileMayGive) {
  for (const auto& e : Effects()) {
    for (const auto& p : e->parameters()) {
      SCOPED_TRACE(e->name() + " " + p.name);
      EXPECT_GE(p.start, p.lo);
      EXPECT_LE(p.start, p.hi);
      // A default stands in for a file's value (0 may mean "derived", e.g. a mode spacing;
      // NaN a form, e.g. a mode hop's centred power-on without a centre).
      if (p.default_value && !std::isnan(*p.default_value)) {
        EXPECT_GE(*p.default_value, p.file_lo);
        EXPECT_LE(*p.default_value, p.file_hi);
      }
      if (p.prior_factor > 0.0) {
        EXPECT_GT(p.prior_factor, 1.0);  // a log-normal sd of log(factor)
      }
    }
  }
}

TEST(EffectRegistry, ALinkOrMassConductsAsLittleAsAThinSensorLead) {
  // The conductance's plausible low end is a thin sensor lead's (1e-6 W/K: 0.1 mm constantan
  // over 10 cm, 1.7e-6), not 1e-4: the reference generator's links of 7.5e-5 and 9.8e-5 W/K
  // were set aside as implausible stand-ins. Below it, a fitted link is a stand-in.
  for (const char* name : {"thermal.missing_link", "thermal.missing_mass"}) {
    SCOPED_TRACE(name);
    const Effect& e = RequireEffect(name);
    ParameterMap p;
    for (const auto& q : e.parameters()) p[q.name] = q.start;
    p["conductance_W_per_K"] = 8e-5;
    EXPECT_TRUE(e.OutsidePlausibleRange(p).empty());
    p["conductance_W_per_K"] = 1e-7;
    const auto v = e.OutsidePlausibleRange(p);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v.front().parameter->name, "conductance_W_per_K");
  }
}

TEST(EffectRegistry, EveryEffectHasTargetsInTheDefaultGyro) {
  const GyroConfig g = test::NoiselessDefaultGyro();
  for (const auto& e : Effects()) EXPECT_FALSE(e->Targets(SpaceOf(g)).empty()) << e->name();
}

TEST(EffectRegistry, EveryEffectAppliedAtItsStartChangesTheSimulatedTrace) {
  const GyroConfig nominal = test::NoiselessDefaultGyro();
  const sim::Run base = SimulateRun(nominal, test::RiseFall(), 1, 0);
  for (const auto& e : Effects()) {
    const std::string target = e->Targets(SpaceOf(nominal)).front();
    SCOPED_TRACE(e->name() + " on " + target);
    GyroConfig with = nominal;
    ApplyEffect({e->name(), target, e->Start()}, with);
    ASSERT_EQ(with.effects.size(), nominal.effects.size() + 1);
    const sim::Run run = SimulateRun(with, test::RiseFall(), 1, 0);
    ASSERT_EQ(run.columns.size(), base.columns.size());
    // A nonlinear effect (radiation, power drift) is integrated by CVODE instead of the exact
    // propagator, which alone moves the temperatures by its error, ~1e-7 °C at the default
    // tolerance of 1e-9 over hours; 1e-4 (°C or °/h) is a thousand times that, and every start
    // moves the trace by 1e-2 or more (the smallest: the 0.01 °C offset).
    EXPECT_GT(LargestDifference(run, base), 1e-4);
  }
}

TEST(EffectRegistry, AnEffectAppendsToTheNetworkWhatItSaysItDoes) {
  // The gyro writer (io/gyro_toml.h) drops what an effect appended to get the gyro without it.
  const GyroConfig nominal = test::NoiselessDefaultGyro();
  for (const auto& e : Effects()) {
    const std::string target = e->Targets(SpaceOf(nominal)).front();
    SCOPED_TRACE(e->name() + " on " + target);
    GyroConfig with = nominal;
    ApplyEffect({e->name(), target, e->Start()}, with);
    const Effect::Appended added = e->AppendsToNetwork();
    EXPECT_EQ(with.network.nodes.size(), nominal.network.nodes.size() + added.nodes);
    EXPECT_EQ(with.network.links.size(), nominal.network.links.size() + added.links);
    EXPECT_EQ(with.network.radiation.size(), nominal.network.radiation.size() + added.radiation);
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
  // The term each effect's own function gives at its start, along the track: expected[k].
  struct Case {
    std::string effect, target;
    std::function<std::vector<double>(const ParameterMap&)> term;
    ParameterMap given = {};  ///< parameters other than the start's
  };
  // A mode hop powered on centred (no centre_C), and locked by an absolute centre 7.5 °C above
  // the block's first temperature (0.25 of the start's 30 °C spacing, so the travel starts off
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
    const Effect& effect = RequireEffect(c.effect);
    ParameterMap p = effect.Start();
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

TEST(BiasPhysics, ThePlayEffectIsNotADiagnosisCandidate) {
  const GyroConfig nominal = NominalForBiasTerms();
  const Track x = SmoothCycle(static_cast<int>(nominal.network.nodes.size()));
  const ColumnGain gain = [](const std::vector<std::vector<double>>&) { return 0.0; };
  EXPECT_TRUE(RequireEffect("bias.play").Regressors(SpaceOf(nominal), {&x.T}, gain).empty());
  EXPECT_FALSE(RequireEffect("bias.play").ComputedFromTracks());
}

/// v less its mean.
std::vector<double> Centred(std::vector<double> v) {
  const double mean = Mean(v);
  for (double& x : v) x -= mean;
  return v;
}

TEST(BiasPhysics, ABiasEffectsRegressorFittedToWhatItAddsGivesBackItsParameters) {
  const GyroConfig nominal = NominalForBiasTerms();
  const Track x = SmoothCycle(static_cast<int>(nominal.network.nodes.size()));
  const std::vector<double> base = BiasAlong(nominal.bias, x);
  // Each effect at its start. A mode hop powered on centred, and at a centre a quarter spacing
  // off the track's start, with and without hysteresis (see the test above), at a range of
  // 0.61: the start's 0.6 puts a sample of this track's block exactly on a reset threshold
  // (T = 38 °C), where only 0.6 itself gives the pattern and no search can land.
  struct Case {
    std::string effect;
    ParameterMap given;
  };
  std::vector<Case> cases;
  for (const auto& e : Effects())
    // bias.play has no regressor: diagnose does not try it (its width is a shape the linear
    // bias search cannot fit; sim/effects/play.h). BiasPhysics.ThePlayEffectIsNotADiagnosisCandidate.
    if (e->kind() == EffectKind::kBias && e->name() != "bias.mode_hop" && e->name() != "bias.play")
      cases.push_back({e->name(), {}});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const ParameterMap& given :
       std::vector<ParameterMap>{{{"centre_C", nan}, {"range_modes", 0.61}},
                                 {{"centre_C", 27.5}, {"range_modes", 0.61}},
                                 {{"centre_C", 27.5}, {"range_modes", 0.5}}})
    cases.push_back({"bias.mode_hop", given});
  for (const auto& c : cases) {
    const Effect* e = &RequireEffect(c.effect);
    SCOPED_TRACE(e->name() + (c.given.count("centre_C") ? " centre " + std::to_string(c.given.at("centre_C")) : "") +
                 (c.given.count("range_modes") ? " range " + std::to_string(c.given.at("range_modes")) : ""));
    ParameterMap applied = e->Start();
    for (const auto& [key, v] : c.given) applied[key] = v;
    const std::string target = e->Targets(SpaceOf(nominal)).front();
    GyroConfig with = nominal;
    ApplyEffect({e->name(), target, applied}, with);
    const std::vector<double> b = BiasAlong(with.bias, x);
    std::vector<double> added(b.size());
    for (size_t k = 0; k < b.size(); ++k) added[k] = b[k] - base[k];
    const std::vector<double> y = Centred(added);
    // The gain diagnose gives (sim::ColumnGain), here against the added bias alone: the drop of
    // its sum of squares, both centred (the runs' offsets).
    const ColumnGain gain = [&](const std::vector<std::vector<double>>& column) {
      const std::vector<double> v = Centred(column[0]);
      double xy = 0.0, xx = 0.0;
      for (size_t k = 0; k < v.size(); ++k) {
        xy += v[k] * y[k];
        xx += v[k] * v[k];
      }
      return xx > 0.0 ? xy * xy / xx : 0.0;
    };
    // Of the regressors on this target, the one that explains most of the added bias.
    const std::vector<BiasRegressor> regs = e->Regressors(SpaceOf(with), {&x.T}, gain);
    const BiasRegressor* reg = nullptr;
    double best = -1.0;
    for (const auto& r : regs) {
      if (r.target != target) continue;
      std::vector<double> column;
      for (size_t k = 0; k < b.size(); ++k) column.push_back(r.column(NodeTrack{x.T, x.Tdot}, k, 0));
      const double g = gain({column});
      if (g > best) best = g, reg = &r;
    }
    ASSERT_NE(reg, nullptr);
    // Least squares of the added bias on the column (both centred): the coefficient diagnose
    // would report.
    std::vector<double> column;
    for (size_t k = 0; k < b.size(); ++k) column.push_back(reg->column(NodeTrack{x.T, x.Tdot}, k, 0));
    const std::vector<double> v = Centred(column);
    double xy = 0.0, xx = 0.0;
    for (size_t k = 0; k < b.size(); ++k) {
      xy += v[k] * y[k];
      xx += v[k] * v[k];
    }
    ASSERT_GT(xx, 0.0);
    const double coefficient = xy / xx;
    // The added bias is exactly c times the column up to a constant (a hysteresis with
    // k_cooling = 0, a mode hop's steps less the travel it resets, and an off-centre power-on's
    // constant): to the rounding of a ~1 °/h bias (9e-16 measured); 1e-12 is margin.
    for (size_t k = 0; k < b.size(); ++k) EXPECT_NEAR(y[k], coefficient * v[k], 1e-12) << "sample " << k;
    // Reported, the parameters are the applied ones: relative 1e-9 covers the rounding of the
    // least squares over 2000 samples (below 1e-15 measured) with margin. A mode hop's spacing,
    // centre and range are known only as far as the track tells their patterns apart: the
    // reported ones give the applied ones' mode index, up to a constant.
    const ParameterMap reported = e->FromReported(reg->parameters(coefficient));
    if (e->name() != "bias.mode_hop") {
      for (const auto& [key, value] : reported)
        EXPECT_NEAR(value, applied.at(key), 1e-9 * std::max(1.0, std::abs(value))) << key;
      continue;
    }
    EXPECT_NEAR(reported.at("step_dph"), applied.at("step_dph"), 1e-9);
    auto shape_of = [](const ParameterMap& p) {
      const auto centre = p.find("centre_C");
      const bool centred = centre == p.end() || std::isnan(centre->second);
      return ModeHopEffect::Shape{p.at("mode_spacing_C"), p.at("range_modes"), centred ? 0.0 : centre->second, centred};
    };
    bool hops = false;
    const auto truth = ModeHopEffect::ModeIndex({&x.T}, with.bias.node, shape_of(applied), &hops);
    const auto found = ModeHopEffect::ModeIndex({&x.T}, with.bias.node, shape_of(reported), &hops);
    // Mode indices are integers: equal up to a constant means equal steps from the first.
    for (size_t k = 0; k < truth[0].size(); ++k)
      ASSERT_EQ(found[0][k] - found[0][0], truth[0][k] - truth[0][0]) << "sample " << k;
  }
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
