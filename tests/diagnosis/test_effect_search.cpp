// How diagnose searches the effect catalog (diagnosis/catalog/effect_search.h): one entry per
// effect of sim's catalog, in its order; every start changes the simulation; a bias effect's
// regressor is its physics' term at unit coefficient, so fitted to what the effect adds it gives
// back the effect's parameters.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include "diagnosis/catalog/effect_search.h"
#include "diagnosis/catalog/mode_hop_search.h"
#include "sim/bias_model.h"
#include "sim/effect_registry.h"
#include "sim/effects/mode_hop.h"
#include "sim/errors.h"
#include "sim/simulator.h"
#include "sim/stats.h"
#include "tests/sim/test_helpers.h"

namespace rlg::diagnosis {
namespace {

using sim::ParameterMap;
using test::BiasAlong;
using test::NominalForBiasTerms;
using test::SmoothCycle;
using test::Track;

const std::vector<std::string> kChannels = {"T1", "T2", "T3", "T4"};

TargetSpace SpaceOf(const sim::GyroConfig& g) {
  return {g, static_cast<int>(g.network.nodes.size()), kChannels};
}

/// Largest absolute difference over every column of two runs of the same shape.
double LargestDifference(const sim::Run& a, const sim::Run& b) {
  double d = 0.0;
  for (size_t c = 0; c < a.columns.size(); ++c)
    for (size_t k = 0; k < a.size(); ++k) d = std::max(d, std::abs(a.columns[c][k] - b.columns[c][k]));
  return d;
}

TEST(EffectSearch, TheBiasEffectsComputedFromTracksAreTheRateTheGradientAndHysteresis) {
  // What diagnose tries on measured channels without a thermal network: not a mode hop, whose
  // term needs the cavity's length and expansion from a gyro file.
  std::vector<std::string> from_tracks;
  for (const auto& e : EffectSearches())
    if (e->ComputedFromTracks()) from_tracks.push_back(e->name());
  EXPECT_EQ(from_tracks, (std::vector<std::string>{"bias.temperature_rate", "bias.gradient", "bias.hysteresis"}));
}

TEST(EffectSearch, TheTableHoldsEveryCatalogEffectInItsOrder) {
  std::vector<std::string> names;
  for (const auto& e : EffectSearches()) {
    names.push_back(e->name());
    EXPECT_EQ(&e->effect(), sim::FindEffect(e->name()));
    EXPECT_EQ(FindSearch(e->name()), e.get());
  }
  EXPECT_EQ(names, sim::EffectNames());
  EXPECT_EQ(FindSearch("poly.lag"), nullptr);  // a model-family term: no catalog effect
  EXPECT_THROW(RequireSearch("bias.wobble"), InputError);
}

TEST(EffectSearch, StartsLieInTheirPlausibleRangeAndPriorsAreWiderThanOne) {
  for (const auto& e : EffectSearches()) {
    for (const auto& p : e->effect().parameters()) {
      SCOPED_TRACE(e->name() + " " + p.name);
      if (p.reference) {
        // Held at its default and not reported.
        EXPECT_TRUE(e->Fixed(p.name));
        EXPECT_EQ(e->Start().at(p.name), *p.default_value);
        EXPECT_EQ(e->Reported(e->Start()).count(p.name), 0u);
        continue;
      }
      const ParameterSearch& q = e->Parameter(p.name);  // every other parameter has a search
      EXPECT_GE(q.start, p.lo);
      EXPECT_LE(q.start, p.hi);
      if (q.prior_factor > 0.0) {
        EXPECT_GT(q.prior_factor, 1.0);  // a log-normal sd of log(factor)
        EXPECT_EQ(q.fit, ParameterSearch::Fit::kShape);
      }
    }
  }
}

TEST(EffectSearch, APlausibleSizeIsOneInsideTheCatalogsRangeOfEitherSign) {
  // The ranges of sim/effects/ (docs/physics.md): a rate term within +-1 °/h per °C/min, a
  // radiation eps A of 1e-6 to 0.2 m² (positive only), a hysteresis difference within +-0.5
  // °/h/°C (applied as k_heating = the difference, k_cooling = 0).
  const std::string rate = "k_dph_per_C_per_min";
  EXPECT_TRUE(PlausibleSize("bias.temperature_rate", {{rate, 0.1}}, rate, 0.99));
  EXPECT_FALSE(PlausibleSize("bias.temperature_rate", {{rate, 0.1}}, rate, 1.42));
  EXPECT_TRUE(PlausibleSize("thermal.radiation", {{"emissivity_area_m2", 1e-4}}, "emissivity_area_m2", 1e-5));
  EXPECT_FALSE(PlausibleSize("thermal.radiation", {{"emissivity_area_m2", 1e-4}}, "emissivity_area_m2", 0.3));
  EXPECT_FALSE(PlausibleSize("thermal.radiation", {{"emissivity_area_m2", 1e-4}}, "emissivity_area_m2", 1e-7));
  const std::string d = "k_heating_minus_cooling_dph_per_C";
  EXPECT_TRUE(PlausibleSize("bias.hysteresis", {{d, 0.001}}, d, 0.4));
  EXPECT_FALSE(PlausibleSize("bias.hysteresis", {{d, 0.001}}, d, 0.6));
  // No size (never detected or named apart) and a cause outside the catalog are not marked.
  EXPECT_TRUE(PlausibleSize("bias.temperature_rate", {{rate, 0.1}}, rate, std::numeric_limits<double>::infinity()));
  EXPECT_TRUE(PlausibleSize("poly.lag", {}, "tau_s", 1e9));
}

TEST(EffectSearch, ALinkOrMassConductsAsLittleAsAThinSensorLead) {
  // The conductance's plausible low end is a thin sensor lead's (1e-6 W/K: 0.1 mm constantan
  // over 10 cm, 1.7e-6), not 1e-4: the reference generator's links of 7.5e-5 and 9.8e-5 W/K
  // were set aside as implausible stand-ins. Below it, a fitted link is a stand-in.
  for (const char* name : {"thermal.missing_link", "thermal.missing_mass"}) {
    SCOPED_TRACE(name);
    const EffectSearch& e = RequireSearch(name);
    ParameterMap p;
    p = e.Start();
    p["conductance_W_per_K"] = 8e-5;
    EXPECT_TRUE(e.OutsidePlausibleRange(p).empty());
    p["conductance_W_per_K"] = 1e-7;
    const auto v = e.OutsidePlausibleRange(p);
    ASSERT_EQ(v.size(), 1u);
    EXPECT_EQ(v.front().parameter->name, "conductance_W_per_K");
  }
}

TEST(EffectSearch, EveryEffectHasTargetsInTheDefaultGyro) {
  const sim::GyroConfig g = test::NoiselessDefaultGyro();
  for (const auto& e : EffectSearches()) EXPECT_FALSE(e->Targets(SpaceOf(g)).empty()) << e->name();
}

TEST(EffectSearch, EveryEffectAppliedAtItsStartChangesTheSimulatedTrace) {
  const sim::GyroConfig nominal = test::NoiselessDefaultGyro();
  const sim::Run base = sim::SimulateRun(nominal, test::RiseFall(), 1, 0);
  for (const auto& e : EffectSearches()) {
    const std::string target = e->Targets(SpaceOf(nominal)).front();
    SCOPED_TRACE(e->name() + " on " + target);
    sim::GyroConfig with = nominal;
    sim::ApplyEffect({e->name(), target, e->Start()}, with);
    ASSERT_EQ(with.effects.size(), nominal.effects.size() + 1);
    const sim::Run run = sim::SimulateRun(with, test::RiseFall(), 1, 0);
    ASSERT_EQ(run.columns.size(), base.columns.size());
    // A nonlinear effect (radiation, power drift) is integrated by CVODE instead of the exact
    // propagator, which alone moves the temperatures by its error, ~1e-7 °C at the default
    // tolerance of 1e-9 over hours; 1e-4 (°C or °/h) is a thousand times that, and every start
    // moves the trace by 1e-2 or more (the smallest: the 0.01 °C offset).
    EXPECT_GT(LargestDifference(run, base), 1e-4);
  }
}

TEST(EffectSearch, AnEffectAppendsToTheNetworkWhatItSaysItDoes) {
  // The gyro writer (io/gyro_toml.h) drops what an effect appended to get the gyro without it.
  const sim::GyroConfig nominal = test::NoiselessDefaultGyro();
  for (const auto& e : EffectSearches()) {
    const std::string target = e->Targets(SpaceOf(nominal)).front();
    SCOPED_TRACE(e->name() + " on " + target);
    sim::GyroConfig with = nominal;
    sim::ApplyEffect({e->name(), target, e->Start()}, with);
    const sim::Effect::Appended added = e->effect().AppendsToNetwork();
    EXPECT_EQ(with.network.nodes.size(), nominal.network.nodes.size() + added.nodes);
    EXPECT_EQ(with.network.links.size(), nominal.network.links.size() + added.links);
    EXPECT_EQ(with.network.radiation.size(), nominal.network.radiation.size() + added.radiation);
  }
}

TEST(EffectSearch, ThePlayEffectIsNotADiagnosisCandidate) {
  const sim::GyroConfig nominal = NominalForBiasTerms();
  const Track x = SmoothCycle(static_cast<int>(nominal.network.nodes.size()));
  const GainOfColumn gain([](const RunColumn&) { return 0.0; });
  EXPECT_TRUE(RequireSearch("bias.play").Regressors(SpaceOf(nominal), {&x.T}, gain).empty());
  EXPECT_FALSE(RequireSearch("bias.play").ComputedFromTracks());
}

/// v less its mean.
std::vector<double> Centred(std::vector<double> v) {
  const double mean = sim::Mean(v);
  for (double& x : v) x -= mean;
  return v;
}

/// A gain that keeps each key's value (as the bias bootstrap's replicates keep each key's
/// projection): ColumnGain::Keyed's contract is that a key names one column.
class KeepingGain final : public ColumnGain {
 public:
  explicit KeepingGain(std::function<double(const RunColumn&)> gain) : gain_(std::move(gain)) {}
  double operator()(const RunColumn& column) const override { return gain_(column); }
  double Keyed(const std::vector<double>& key, const std::function<std::optional<RunColumn>()>& make) const override {
    ++asked;
    const auto it = kept.find(key);
    if (it != kept.end()) return it->second;
    const std::optional<RunColumn> column = make();
    return kept[key] = column ? gain_(*column) : -1.0;
  }
  mutable std::map<std::vector<double>, double> kept;
  mutable size_t asked = 0;

 private:
  std::function<double(const RunColumn&)> gain_;
};

TEST(EffectSearch, AModeHopsShapeKeysNameItsColumnSoKeptGainsFindTheSameShape) {
  // A mode hop off centre, with hysteresis (range 0.5), searched with a gain that keeps nothing,
  // then twice with one that keeps each grid shape's gain by key: the second time from what
  // the first kept. A key that left out what makes a column (the form, the range) would give
  // one grid shape another's gain, and the search another shape.
  const sim::GyroConfig nominal = NominalForBiasTerms();
  const Track x = SmoothCycle(static_cast<int>(nominal.network.nodes.size()));
  const EffectSearch& e = RequireSearch("bias.mode_hop");
  ParameterMap applied = e.Start();
  applied["centre_C"] = 27.5;
  applied["range_modes"] = 0.5;
  sim::GyroConfig with = nominal;
  sim::ApplyEffect({e.name(), e.Targets(SpaceOf(nominal)).front(), applied}, with);
  const std::vector<double> base = BiasAlong(nominal.bias, x), b = BiasAlong(with.bias, x);
  std::vector<double> added(b.size());
  for (size_t k = 0; k < b.size(); ++k) added[k] = b[k] - base[k];
  const std::vector<double> y = Centred(added);
  const auto gain_of = [&](const RunColumn& column) {
    const std::vector<double> v = Centred(column[0]);
    double xy = 0.0, xx = 0.0;
    for (size_t k = 0; k < v.size(); ++k) xy += v[k] * y[k], xx += v[k] * v[k];
    return xx > 0.0 ? xy * xy / xx : 0.0;
  };
  const auto shapes = [&](const ColumnGain& gain) {
    std::vector<ParameterMap> out;
    for (const auto& r : e.Regressors(SpaceOf(with), {&x.T}, gain)) out.push_back(r.parameters(1.0));
    return out;
  };
  const std::vector<ParameterMap> plain = shapes(GainOfColumn(gain_of));
  ASSERT_EQ(plain.size(), 2u);  // both power-on forms
  const KeepingGain keeping(gain_of);
  EXPECT_EQ(shapes(keeping), plain);
  // The grid went through the keys, each of its shapes under a key of its own.
  EXPECT_GT(keeping.asked, 100u);
  EXPECT_EQ(keeping.kept.size(), keeping.asked);
  EXPECT_EQ(shapes(keeping), plain);  // and again, from what was kept
  EXPECT_EQ(keeping.kept.size() * 2, keeping.asked);
}

/// The mode index by its definition: the simulator's path-length control, sample by sample.
RunColumn ModeIndexSampleBySample(const std::vector<const Eigen::MatrixXd*>& T_runs, int node, const ModeHopShape& s,
                                  bool* hops) {
  RunColumn out;
  *hops = false;
  for (const Eigen::MatrixXd* T : T_runs) {
    out.emplace_back();
    if (T->cols() == 0) continue;
    const sim::PlcLock on =
        sim::PowerOn((*T)(node, 0), s.centred ? std::numeric_limits<double>::quiet_NaN() : s.centre_C, s.spacing_C);
    int mode = on.mode;
    for (Eigen::Index k = 0; k < T->cols(); ++k) {
      sim::PathLengthTravel((*T)(node, k), on.T_lock_C, s.spacing_C, s.range_modes, mode);
      out.back().push_back(sim::ModeHopEffect::Bias_dph(1.0, mode));
      *hops = *hops || mode != on.mode;
    }
  }
  return out;
}

TEST(EffectSearch, AModeIndexThatSkipsStretchesWithoutAResetIsTheSampleBySampleOne) {
  // ModeTracks takes a stretch of 64 samples whole when the travel at its extreme temperatures
  // resets at neither. The tracks: a smooth cycle; one that dithers by 1e-12 °C about the first
  // reset edge of a 10 °C centred shape at range 0.5 (samples on both sides in every stretch,
  // and some exactly on it: a test with < for <= would skip them); one with NaN samples (they
  // move no mode); a run shorter than a stretch; an empty one. The numbers must be equal,
  // not close: the search's shapes are chosen by these columns.
  const int nodes = 4, node = 1;
  const Track cycle = SmoothCycle(nodes);
  Eigen::MatrixXd dither(nodes, 1000), with_nan(nodes, 300), short_run(nodes, 40), empty(nodes, 0);
  const double T0 = 20.0, edge = T0 + 0.5 * 10.0;
  for (Eigen::Index k = 0; k < dither.cols(); ++k) {
    const double v = k == 0 ? T0 : edge + (k % 3 == 0 ? 0.0 : (k % 3 == 1 ? 1e-12 : -1e-12)) + (k > 600 ? 7.0 : 0.0);
    dither.col(k).setConstant(v);
  }
  for (Eigen::Index k = 0; k < with_nan.cols(); ++k)
    with_nan.col(k).setConstant(k % 50 == 7 || (k >= 128 && k < 192) ? std::numeric_limits<double>::quiet_NaN() : 20.0 + 0.2 * k);
  for (Eigen::Index k = 0; k < short_run.cols(); ++k) short_run.col(k).setConstant(30.0 - 0.5 * k);
  const std::vector<const Eigen::MatrixXd*> runs = {&cycle.T, &dither, &with_nan, &short_run, &empty};
  const ModeTracks tracks(runs, node);
  int shapes = 0, hopping = 0;
  for (double spacing : {-10.0, 3.0, 4.7, 10.0, 13.0, 29.9, 61.0, 150.0}) {  // -10: the order of the extremes reversed
    for (double range : {0.5, 0.5000000001, 0.65, 0.85, 2.0}) {
      std::vector<ModeHopShape> forms = {{spacing, range, 0.0, true}};
      for (double centre : {T0, edge, 23.3, -7.0}) forms.push_back({spacing, range, centre, false});
      for (const ModeHopShape& s : forms) {
        bool hops = false, hops_by_definition = false;
        const RunColumn got = tracks.ModeIndex(s, &hops);
        EXPECT_EQ(got, ModeIndexSampleBySample(runs, node, s, &hops_by_definition))
            << "spacing " << s.spacing_C << ", range " << s.range_modes << (s.centred ? "" : ", centre ") << s.centre_C;
        EXPECT_EQ(hops, hops_by_definition);
        EXPECT_EQ(ModeIndex(runs, node, s, &hops), got);  // the one-shape function is the same
        ++shapes;
        hopping += hops_by_definition ? 1 : 0;
      }
    }
  }
  // Both kinds were tried: shapes whose runs hop and shapes whose runs do not.
  EXPECT_GT(hopping, shapes / 4);
  EXPECT_LT(hopping, shapes);
}

TEST(EffectSearch, ABiasEffectsRegressorFittedToWhatItAddsGivesBackItsParameters) {
  const sim::GyroConfig nominal = NominalForBiasTerms();
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
  for (const auto& e : EffectSearches())
    // bias.play has no regressor: diagnose does not try it (its width is a shape the linear
    // bias search cannot fit; diagnosis/catalog/bias_searches.cpp). EffectSearch.ThePlayEffectIsNotADiagnosisCandidate.
    if (e->effect().kind() == sim::EffectKind::kBias && e->name() != "bias.mode_hop" && e->name() != "bias.play")
      cases.push_back({e->name(), {}});
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const ParameterMap& given :
       std::vector<ParameterMap>{{{"centre_C", nan}, {"range_modes", 0.61}},
                                 {{"centre_C", 27.5}, {"range_modes", 0.61}},
                                 {{"centre_C", 27.5}, {"range_modes", 0.5}}})
    cases.push_back({"bias.mode_hop", given});
  for (const auto& c : cases) {
    const EffectSearch* e = &RequireSearch(c.effect);
    SCOPED_TRACE(e->name() + (c.given.count("centre_C") ? " centre " + std::to_string(c.given.at("centre_C")) : "") +
                 (c.given.count("range_modes") ? " range " + std::to_string(c.given.at("range_modes")) : ""));
    ParameterMap applied = e->Start();
    for (const auto& [key, v] : c.given) applied[key] = v;
    const std::string target = e->Targets(SpaceOf(nominal)).front();
    sim::GyroConfig with = nominal;
    sim::ApplyEffect({e->name(), target, applied}, with);
    const std::vector<double> b = BiasAlong(with.bias, x);
    std::vector<double> added(b.size());
    for (size_t k = 0; k < b.size(); ++k) added[k] = b[k] - base[k];
    const std::vector<double> y = Centred(added);
    // The gain diagnose gives (ColumnGain), here against the added bias alone: the drop of
    // its sum of squares, both centred (the runs' offsets).
    const GainOfColumn gain([&](const RunColumn& column) {
      const std::vector<double> v = Centred(column[0]);
      double xy = 0.0, xx = 0.0;
      for (size_t k = 0; k < v.size(); ++k) {
        xy += v[k] * y[k];
        xx += v[k] * v[k];
      }
      return xx > 0.0 ? xy * xy / xx : 0.0;
    });
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
      return ModeHopShape{p.at("mode_spacing_C"), p.at("range_modes"), centred ? 0.0 : centre->second, centred};
    };
    bool hops = false;
    const auto truth = ModeIndex({&x.T}, with.bias.node, shape_of(applied), &hops);
    const auto found = ModeIndex({&x.T}, with.bias.node, shape_of(reported), &hops);
    // Mode indices are integers: equal up to a constant means equal steps from the first.
    for (size_t k = 0; k < truth[0].size(); ++k)
      ASSERT_EQ(found[0][k] - found[0][0], truth[0][k] - truth[0][0]) << "sample " << k;
  }
}

}  // namespace
}  // namespace rlg::diagnosis
