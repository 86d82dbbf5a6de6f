// The effect catalog as objects (sim/effect_registry.h): every effect is registered in SPEC
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
#include "sim/effects/temperature_rate.h"
#include "sim/errors.h"
#include "sim/simulator.h"
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

TEST(EffectRegistry, ListsTheTenEffectsInSpecOrder) {
  const std::vector<std::string> spec = {"thermal.missing_mass", "thermal.missing_link", "thermal.power_drift",
                                         "thermal.radiation",    "sensor.lag",           "sensor.offset",
                                         "bias.temperature_rate", "bias.gradient",       "bias.hysteresis",
                                         "bias.mode_hop"};
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
    }
  }
}

TEST(EffectRegistry, StartsLieInTheirPlausibleRangeAndDefaultsInWhatAFileMayGive) {
  for (const auto& e : Effects()) {
    for (const auto& p : e->parameters()) {
      SCOPED_TRACE(e->name() + " " + p.name);
      EXPECT_GE(p.start, p.lo);
      EXPECT_LE(p.start, p.hi);
      // A default stands in for a file's value (0 may mean "derived", e.g. a mode spacing).
      if (p.default_value) {
        EXPECT_GE(*p.default_value, p.file_lo);
        EXPECT_LE(*p.default_value, p.file_hi);
      }
      if (p.prior_factor > 0.0) {
        EXPECT_GT(p.prior_factor, 1.0);  // a log-normal sd of log(factor)
      }
    }
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
  // The gyro writer (sim/gyro_toml.h) drops what an effect appended to get the gyro without it.
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
  };
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
      {"bias.mode_hop", "block",
       [&](const ParameterMap& p) {
         // The steps, and the path-length control's travel, which resets with each hop.
         std::vector<double> v;
         int mode = 0, never = 0;
         const double lock = x.T(block, 0), spacing = p.at("mode_spacing_C"), plc = nominal.bias.plc_dph_per_wavelength;
         for (Eigen::Index k = 0; k < x.T.cols(); ++k) {
           const double u = PathLengthTravel(x.T(block, k), lock, spacing, p.at("range_modes"), mode);
           const double u_unlimited = PathLengthTravel(x.T(block, k), lock, spacing, std::numeric_limits<double>::infinity(), never);
           v.push_back(ModeHopEffect::Bias_dph(p.at("step_dph"), mode) + plc * (u - u_unlimited));
         }
         return v;
       }},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.effect);
    const Effect& effect = RequireEffect(c.effect);
    GyroConfig with = nominal;
    ApplyEffect({c.effect, c.target, effect.Start()}, with);
    const std::vector<double> b = BiasAlong(with.bias, x), expected = c.term(effect.Start());
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

TEST(BiasPhysics, ABiasEffectsRegressorFittedToWhatItAddsGivesBackItsParameters) {
  const GyroConfig nominal = NominalForBiasTerms();
  const Track x = SmoothCycle(static_cast<int>(nominal.network.nodes.size()));
  const std::vector<double> base = BiasAlong(nominal.bias, x);
  for (const auto& e : Effects()) {
    if (e->kind() != EffectKind::kBias) continue;
    SCOPED_TRACE(e->name());
    const std::string target = e->Targets(SpaceOf(nominal)).front();
    GyroConfig with = nominal;
    ApplyEffect({e->name(), target, e->Start()}, with);
    const std::vector<double> b = BiasAlong(with.bias, x);
    // The regressors on this target; of a mode hop's ranges, the one applied.
    const std::vector<BiasRegressor> regs = e->Regressors(SpaceOf(with), {&x.T});
    const BiasRegressor* reg = nullptr;
    for (const auto& r : regs) {
      const ParameterMap p = r.parameters(1.0);
      if (r.target == target && (!p.count("range_modes") || p.at("range_modes") == e->Start().at("range_modes"))) reg = &r;
    }
    ASSERT_NE(reg, nullptr);
    // Least squares of the added bias on the column: the coefficient diagnose would report.
    double xy = 0.0, xx = 0.0;
    std::vector<double> column;
    for (size_t k = 0; k < b.size(); ++k) {
      column.push_back(reg->column(NodeTrack{x.T, x.Tdot}, k, 0));
      xy += column[k] * (b[k] - base[k]);
      xx += column[k] * column[k];
    }
    ASSERT_GT(xx, 0.0);
    const double c = xy / xx;
    // The added bias is exactly c times the column (a hysteresis with k_cooling = 0 and a mode
    // hop's steps less the travel it resets alike): to the rounding of a ~1 °/h bias (9e-16
    // measured); 1e-12 is margin.
    for (size_t k = 0; k < b.size(); ++k) EXPECT_NEAR(b[k] - base[k], c * column[k], 1e-12) << "sample " << k;
    // Reported and applied back, the parameters are the start's: relative 1e-9 covers the
    // rounding of the least squares over 2000 samples (below 1e-15 measured) with margin.
    for (const auto& [key, v] : e->FromReported(reg->parameters(c)))
      EXPECT_NEAR(v, e->Start().at(key), 1e-9 * std::max(1.0, std::abs(v))) << key;
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
