// Diagnosis end to end on clear hidden effects, several times the strength of the blind
// catalog test (tests/diagnosis/test_diagnose.cpp; README "Diagnosis status"), 2-11 s each.
// Blind: the data are simulated here; Diagnose sees the data and the nominal gyro only.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <set>

#include "diagnosis/diagnose.h"
#include "diagnosis/report.h"
#include "io/gyro_file.h"
#include "io/scenario_file.h"
#include "sim/noise.h"
#include "tests/diagnosis/hidden_effects.h"
#include "tools/source_dir.h"

namespace rlg::diagnosis {
namespace {

class ClearEffect : public ::testing::TestWithParam<test::ClearCase> {};

TEST_P(ClearEffect, IsNamedWithItsTargetAndParameter) { test::ExpectClearEffectFound(GetParam()); }

INSTANTIATE_TEST_SUITE_P(
    Diagnose, ClearEffect,
    ::testing::Values(test::ClearCase{"sensor.lag", "T2", "time_constant_s", {{"time_constant_s", 30.0}}},
                      test::ClearCase{"thermal.missing_mass", "block-cabinet", "heat_capacity_J_per_K",
                                      {{"heat_capacity_J_per_K", 200.0}, {"conductance_W_per_K", 0.05}}},
                      // 0.5 °/h per °C/min: ~9x the noise in what the bias calibration leaves
                      // (0.05 was 0.9x: HiddenCases prints 3.4x at 0.193).
                      test::ClearCase{"bias.temperature_rate", "T1", "k_dph_per_C_per_min", {{"k_dph_per_C_per_min", 0.5}}},
                      test::ClearCase{"thermal.missing_link", "anode-cathode", "conductance_W_per_K", {{"conductance_W_per_K", 0.01}}},
                      test::ClearCase{"thermal.radiation", "block-ambient", "emissivity_area_m2", {{"emissivity_area_m2", 0.002}}}),
    [](const auto& info) { return test::TestName(info.param.effect); });

// A mode hop's spacing (Zerodur's expansion is too uncertain for a gyro file
// to fix it), its power-on phase and whether it has hysteresis are searched, not taken from
// the nominal (whose lambda / (L alpha) is 29.4 °C, and whose runs each power on centred).
// Each case hides steps of 0.05 °/h (the hidden catalog's 0.02 at 2.5x: clear, as the cases
// above) in a form the nominal does not have, at a spacing inside docs/physics.md's 15-70 K.
struct HopCase {
  const char* name;
  std::map<std::string, double> parameters;
};

class ModeHopShape : public ::testing::TestWithParam<HopCase> {};

/// The mode index m(t) of a mode hop with `p`'s shape along every run of the diagnosis suite:
/// the bias of a noiseless gyro whose only bias term is that hop at a unit step, less its value
/// at power-on.
std::vector<std::vector<double>> ModeIndexAlongSuite(const std::map<std::string, double>& p) {
  sim::Scenario sc = test::Noiseless(test::DiagnosisScenario());
  sim::BiasParams only;
  only.node = sc.gyro.bias.node;
  only.mode_spacing_C = sc.gyro.bias.mode_spacing_C;
  sc.gyro.bias = only;
  std::map<std::string, double> unit = p;
  unit["step_dph"] = 1.0;
  sim::ApplyEffect({"bias.mode_hop", "block", unit}, sc.gyro);
  std::vector<std::vector<double>> m;
  for (const auto& run : sim::SimulateScenario(sc, sc.seed).runs) {
    std::vector<double> v = run.Column("bias_dph");
    for (double& x : v) x -= run.Column("bias_dph").front();
    m.push_back(std::move(v));
  }
  return m;
}

TEST_P(ModeHopShape, IsSearchedNotTakenFromTheNominal) {
  const HopCase& c = GetParam();
  sim::Scenario sc = test::DiagnosisScenario();
  sim::ApplyEffect({"bias.mode_hop", "block", c.parameters}, sc.gyro);
  const Diagnosis d = Diagnose(sim::SimulateScenario(sc, sc.seed), test::DiagnosisScenario().gyro, DiagnoseOptions{});
  ASSERT_FALSE(d.steps.empty()) << "nothing accepted" << test::TopCandidates(d);
  const Candidate& got = d.steps.front().accepted;
  ASSERT_EQ(got.cause, "bias.mode_hop") << test::TopCandidates(d);
  // 20 %: the pipeline's tolerance for a clear effect's size.
  EXPECT_NEAR(got.parameters.at("step_dph"), c.parameters.at("step_dph"), 0.2 * c.parameters.at("step_dph"));
  // The data show the hops, not the parameters: where a run crosses only some of the edges
  // (hops up, say, and none down), spacing, centre and range trade along the edges it did
  // cross. So the hops must come back: the mode index of the reported shape along the suite is
  // the truth's at all but 1 % of the samples. An edge is placed from 10 s block means, and
  // one misplaced by 0.1 °C moves its hop by 0.1 °C over the block's rate: seconds on a ramp,
  // minutes where a warm-up creeps across it (measured: 6, 11 and 213 samples of 45,005).
  const auto truth = ModeIndexAlongSuite(c.parameters), found = ModeIndexAlongSuite(got.parameters);
  size_t wrong = 0, samples = 0, hops = 0;
  for (size_t r = 0; r < truth.size(); ++r) {
    for (size_t k = 0; k < truth[r].size(); ++k) {
      wrong += truth[r][k] != found[r][k];
      hops += k > 0 && truth[r][k] != truth[r][k - 1];
    }
    samples += truth[r].size();
  }
  EXPECT_GE(hops, 2u) << "the case shows hops";
  EXPECT_LE(static_cast<double>(wrong), 0.01 * static_cast<double>(samples)) << wrong << " of " << samples;
  // The step says that the hops' temperatures, not the parameters, are what the data fix.
  EXPECT_TRUE(std::any_of(d.steps.front().notes.begin(), d.steps.front().notes.end(), [](const std::string& n) {
    return n.rfind("the data fix where bias.mode_hop steps", 0) == 0;
  }));
  // Whether runs power on centred or at a phase of their absolute temperature is told apart.
  EXPECT_EQ(got.parameters.count("centre_C"), c.parameters.count("centre_C")) << "power-on form";
}

INSTANTIATE_TEST_SUITE_P(
    Diagnose, ModeHopShape,
    ::testing::Values(
        HopCase{"reversible_16C", {{"step_dph", 0.05}, {"mode_spacing_C", 16.0}, {"centre_C", 23.0}, {"range_modes", 0.5}}},
        HopCase{"hysteresis_18C_centred", {{"step_dph", 0.05}, {"mode_spacing_C", 18.0}, {"range_modes", 0.7}}},
        HopCase{"hysteresis_24C_phase", {{"step_dph", 0.05}, {"mode_spacing_C", 24.0}, {"centre_C", 5.0}, {"range_modes", 0.75}}}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(HiddenCases, EffectsAreScaledOnWhatACalibrationLeaves) {
  // Every catalog effect on every target it is drawn on reaches the drawn strength (3-6x the
  // noise at 100 s) in the part the calibration cannot take up; the raw effect is then
  // larger, by how much the calibration would absorb.
  for (const auto& entry : test::HiddenCatalog()) {
    std::set<std::string> seen;
    for (uint64_t seed = 1; seen.size() < entry.targets.size() && seed < 200; ++seed) {
      test::HiddenCase truth;
      test::MakeHiddenCase(entry.effect, seed, &truth);
      if (!seen.insert(truth.target).second) continue;
      std::printf("%-22s %-16s strength %.2f raw %.2f %s %.3g\n", entry.effect.c_str(), truth.target.c_str(),
                  truth.strength, truth.raw_strength, truth.checked.c_str(), truth.parameters.at(truth.checked));
      // Three secant steps on a nearly linear effect converge to a few percent of the goal.
      EXPECT_GT(truth.strength, 3.0 * 0.95) << entry.effect << " " << truth.target;
      EXPECT_LT(truth.strength, 6.0 * 1.05) << entry.effect << " " << truth.target;
      EXPECT_GE(truth.raw_strength, truth.strength * 0.999);  // a projection cannot add
    }
    EXPECT_EQ(seen.size(), entry.targets.size()) << entry.effect;
  }
}

TEST(HiddenCases, ALinkInParallelWithAnExistingOneIsTakenUpByTheCalibration) {
  // 0.01 W/K beside the 0.42 W/K block-cabinet link is that link's conductance +2.4 %: one
  // knob. What is left is the linearisation's second order, (0.024)^2 / 2 ~ 3e-4 of the
  // effect, plus the 1e-3 log step's difference error: below 1 % of the effect.
  const sim::Scenario clean = test::Noiseless(test::DiagnosisScenario());
  const test::CalibrationProjector projector(clean);
  const double noise = test::NoiseRms100(test::DiagnosisScenario().gyro, false);
  const auto [raw, left] = projector.Rms({"thermal.missing_link", "block-cabinet", {{"conductance_W_per_K", 0.01}}}, noise, 0.005);
  EXPECT_GT(raw, 10.0 * noise);  // a visible effect
  EXPECT_LT(left, 0.01 * raw);
  // A link to a node pair without one is not a knob: most of it stays.
  const auto [raw2, left2] = projector.Rms({"thermal.missing_link", "anode-cathode", {{"conductance_W_per_K", 0.01}}}, noise, 0.005);
  EXPECT_GT(left2, 0.1 * raw2);
}

TEST(HiddenCases, AGradientAlongTheLangmuirLegIsTakenUpByTheBiasCalibration) {
  // k (T_anode - T_block) is the Langmuir term's own regressor: a linear least-squares fit
  // removes it to round-off. A gradient to the cabinet is not one of them.
  const sim::Scenario clean = test::Noiseless(test::DiagnosisScenario());
  const sim::Trace without = sim::SimulateScenario(clean, 1);
  sim::Scenario with = clean;
  sim::ApplyEffect({"bias.gradient", "anode-block", {{"k_dph_per_C", 0.05}}}, with.gyro);
  const test::BiasProjection p = test::ProjectBias(without, sim::SimulateScenario(with, 1), clean.gyro);
  EXPECT_GT(p.raw, 10.0 * test::NoiseRms100(test::DiagnosisScenario().gyro, true));
  EXPECT_LT(p.left, 1e-9 * p.raw);
  sim::Scenario other = clean;
  sim::ApplyEffect({"bias.gradient", "block-cabinet", {{"k_dph_per_C", 0.05}}}, other.gyro);
  const test::BiasProjection p2 = test::ProjectBias(without, sim::SimulateScenario(other, 1), clean.gyro);
  EXPECT_GT(p2.left, 0.1 * p2.raw);
}

TEST(HiddenCases, ARateIsTheGradientItIsClaimedToBeExactly) {
  // RateAsGradient's identities, checked by simulation: the cathode's rate against the
  // block-cathode gradient, the anode's against anode-cabinet (given the Langmuir anode-block
  // term). Their bias traces differ only by what the bias calibration fits (a per-run offset
  // from C dT/dt = G dT + P, the Langmuir term): nothing is left beyond round-off.
  const sim::Scenario clean = test::Noiseless(test::DiagnosisScenario());
  for (const std::string channel : {"T4", "T2"}) {
    const auto [pair, factor] = test::RateAsGradient(clean.gyro, channel);
    ASSERT_FALSE(pair.empty()) << channel;
    const double k_rate = 0.5;  // 0.1-0.2 °/h of bias: far above the noise
    sim::Scenario rate = clean, gradient = clean;
    sim::ApplyEffect({"bias.temperature_rate", channel, {{"k_dph_per_C_per_min", k_rate}}}, rate.gyro);
    // k dT_n/dt = factor k (T_m - T_n): on the pair "n-m" the coefficient is -factor k.
    sim::ApplyEffect({"bias.gradient", pair, {{"k_dph_per_C", -factor * k_rate}}}, gradient.gyro);
    const sim::Trace a = sim::SimulateScenario(rate, 1), b = sim::SimulateScenario(gradient, 1);
    const double effect = test::ProjectBias(sim::SimulateScenario(clean, 1), a, clean.gyro).raw;
    EXPECT_GT(effect, 10.0 * test::NoiseRms100(test::DiagnosisScenario().gyro, true)) << channel;
    // Left: round-off of the simulation and of the 100 s means, ~1e-12 of the bias.
    EXPECT_LT(test::ProjectBias(b, a, clean.gyro).left, 1e-6 * effect) << channel << " as " << pair;
  }
  // Nodes with a link to ambient have rates of their own.
  EXPECT_TRUE(test::RateAsGradient(clean.gyro, "T1").first.empty());
  EXPECT_TRUE(test::RateAsGradient(clean.gyro, "T3").first.empty());
}

TEST(HiddenCases, TheJudgesNoiseCovarianceIsThatOfTheSimulatorsBlockMeans) {
  // Judge weighs a difference of two answers by the covariance of 100 s means of the gyro's
  // noise (BlockMeanNoiseCovariance). Against the simulator's own GyroNoise: ARW plus one
  // Gauss-Markov term (T = 300 s, a = exp(-1/3) between blocks), 1 s samples over 4e6 s = 40,000
  // blocks. The block means are correlated (a = 0.72), ~7,000 effective values: the lag-0 and
  // lag-1 covariances are estimated to ~2-3 %, so 10 % is ~4 standard errors.
  sim::GyroNoiseParams p;
  p.arw_deg_per_sqrt_h = 0.005;
  p.bias_instability_dph = 0.01;
  p.instability_model = sim::GyroNoiseParams::InstabilityModel::kGaussMarkov;
  p.gauss_markov_time_s = 300.0;
  sim::GyroNoise noise(p, 1.0, 7, 0);
  const int blocks = 40000;
  std::vector<double> m(blocks);
  for (double& v : m) {
    double s = 0.0;
    for (int k = 0; k < 100; ++k) s += noise.Sample(0.0);
    v = s / 100.0;
  }
  double c0 = 0.0, c1 = 0.0;
  for (int i = 0; i < blocks; ++i) {
    c0 += m[i] * m[i];
    if (i > 0) c1 += m[i] * m[i - 1];
  }
  c0 /= blocks;
  c1 /= blocks - 1;
  const Eigen::MatrixXd S = test::BlockMeanNoiseCovariance(p, 100.0, 3);
  EXPECT_NEAR(c0 / S(0, 0), 1.0, 0.10) << c0 << " against " << S(0, 0);
  EXPECT_NEAR(c1 / S(0, 1), 1.0, 0.10) << c1 << " against " << S(0, 1);
  EXPECT_DOUBLE_EQ(S(1, 2), S(0, 1));  // stationary: Toeplitz
}

TEST(HiddenCases, TheJudgeGivesBackATruthFromItsOwnNameItsTwinsAndNoMore) {
  // Judge's regressors must be diagnose's (units, orientation): the truth's own effect under
  // another spelling of its target, or its exact twin, is right with the truth's parameter; an
  // answer the suite separates well is wrong.
  const sim::GyroConfig g = test::NominalForDiagnosis();
  auto hidden = [](std::string effect, std::string target, std::map<std::string, double> p) {
    test::HiddenCase h;
    h.effect = std::move(effect);
    h.target = std::move(target);
    h.parameters = std::move(p);
    return h;
  };
  struct Case {
    test::HiddenCase truth;
    std::string cause, target;  ///< the answer
    bool right;
    std::string key;
    double expected, tolerance;  ///< relative
  };
  // The rate's regressor is a 1 s central difference, the simulator's the exact dT/dt: their
  // 100 s means differ by ~(1 s)^2 T''' / 6, < 1e-4 of T' for the fastest (150 s) node.
  const double rate_tol = 1e-3;
  const double k_rate = 0.3;
  const auto [twin, factor] = test::RateAsGradient(g, "T4");  // "cathode-block"
  const std::vector<Case> cases = {
      {hidden("bias.gradient", "cathode-cabinet", {{"k_dph_per_C", 0.02}}), "bias.gradient", "cabinet-cathode", true,
       "k_dph_per_C", -0.02, 1e-9},  // the answer's orientation
      {hidden("bias.temperature_rate", "T1", {{"k_dph_per_C_per_min", k_rate}}), "bias.temperature_rate", "block", true,
       "k_dph_per_C_per_min", k_rate, rate_tol},
      {hidden("bias.hysteresis", "block", {{"k_heating_dph_per_C", 0.004}, {"k_cooling_dph_per_C", 0.001}}),
       "bias.hysteresis", "T1", true, "k_heating_minus_cooling_dph_per_C", 0.003, 1e-9},
      // The cathode's rate is the cathode-block gradient with k_grad = -60 G / C k_rate.
      {hidden("bias.temperature_rate", "T4", {{"k_dph_per_C_per_min", k_rate}}), "bias.gradient", twin, true,
       "k_dph_per_C", -factor * k_rate, rate_tol},
      // lambda ~ 200 at this size (docs/diagnosis.md, "What diagnosis can tell apart").
      {hidden("bias.gradient", "block-cabinet", {{"k_dph_per_C", 0.015}}), "bias.gradient", "anode-cathode", false, "", 0.0, 0.0},
      {hidden("thermal.missing_link", "anode-cathode", {{"conductance_W_per_K", 0.01}}), "thermal.missing_link", "cathode-cabinet",
       false, "", 0.0, 0.0},
  };
  for (const auto& c : cases) {
    const test::Verdict v = test::Judge(g, c.truth, c.cause, c.target);
    ASSERT_EQ(v.right, c.right) << c.cause << " " << c.target << ": " << v.why;
    if (!c.right) continue;
    EXPECT_EQ(v.key, c.key);
    EXPECT_NEAR(v.expected, c.expected, c.tolerance * std::abs(c.expected)) << c.cause << " " << c.target;
  }
}

TEST(Diagnose, ASingleRunIsScoredOnTimeItWasNotFittedOn) {
  // One run, a clear sensor lag hidden in it. Diagnose cuts it into four pieces, fits on the
  // first and third and scores on the second and fourth (DiagnoseOptions::single_run_pieces).
  // Blind check that the held-out pieces are not used for the fit: shifting T1 and the bias
  // there by far more than the noise leaves every fitted number alone and moves only the
  // held-out RMS.
  sim::Scenario sc = test::DiagnosisScenario();
  sc.runs.resize(1);  // the 20 -> 60 °C ramp, 9000 s
  sim::ApplyEffect({"sensor.lag", "T1", {{"time_constant_s", 60.0}}}, sc.gyro);
  const sim::Trace data = sim::SimulateScenario(sc, sc.seed);
  sim::Trace shifted = data;
  sim::Run& run = shifted.runs.front();
  for (size_t k = 0; k < run.size(); ++k) {
    const int piece = std::min(3, static_cast<int>(run.t_s[k] / 2250.0));
    if (piece % 2 == 0) continue;  // fitted
    run.columns[run.Find("T1")][k] += 0.5;  // ~500x the 100 s noise of T1 (1 mK)
    // Opposite in the two pieces: a per-run bias offset cannot take it up. ~15x the noise.
    run.columns[run.Find("bias_dph")][k] += piece == 1 ? 0.1 : -0.1;
  }
  DiagnoseOptions o;
  o.max_steps = 1;
  const Diagnosis a = Diagnose(data, test::DiagnosisScenario().gyro, o);
  const Diagnosis b = Diagnose(shifted, test::DiagnosisScenario().gyro, o);
  ASSERT_FALSE(a.steps.empty()) << test::TopCandidates(a);
  EXPECT_EQ(a.steps.front().accepted.cause, "sensor.lag") << test::TopCandidates(a);
  EXPECT_EQ(a.steps.front().accepted.target, "T1");
  EXPECT_GT(a.steps.front().accepted.heldout_rms_ratio, 1.2);
  // Fitted numbers: the same to the solver's tolerance. ScoreBlockNoise (which sets it) reads
  // every sample, and T1's shift makes two jumps among 9000 differences; the other channels
  // set its minimum, so nothing moves at all here.
  ASSERT_EQ(a.calibrated.size(), b.calibrated.size());
  for (const auto& [knob, value] : a.calibrated) EXPECT_NEAR(b.calibrated.at(knob), value, 1e-9 * std::abs(value)) << knob;
  ASSERT_EQ(a.first_candidates.size(), b.first_candidates.size());
  for (size_t i = 0; i < a.first_candidates.size(); ++i) {
    const Candidate& ca = a.first_candidates[i];
    for (const Candidate& cb : b.first_candidates) {
      if (cb.cause != ca.cause || cb.target != ca.target) continue;
      for (const auto& [k, v] : ca.parameters) EXPECT_NEAR(cb.parameters.at(k), v, 1e-9 * std::abs(v)) << ca.cause << " " << k;
    }
  }
  // Held-out RMS: the shift s is all there, RMS(e + s) >= RMS(s) - RMS(e). For the bias,
  // RMS(s) is 0.1 on 44 of the 45 held-out 100 s means (one straddles the two pieces).
  EXPECT_GT(b.baseline.temperature_rms_C.at("T1"), 0.5 - a.baseline.temperature_rms_C.at("T1"));
  EXPECT_GT(b.baseline.bias_rms_dph, 0.1 * std::sqrt(44.0 / 45.0) - a.baseline.bias_rms_dph);
}

TEST(Diagnose, ASingleRunWithoutLoggedAmbientKeepsItsFittedAmbientOnHeldOutTime) {
  // Without T_amb the ambient is a per-run nuisance. The held-out stretches of a single run
  // share the one fitted on its other stretches: refitted on them, it would take up a shift
  // of every channel there (an ambient 0.5 °C warmer warms every node by 0.5 °C at steady
  // state) and the held-out RMS would not see it.
  sim::Scenario sc = test::DiagnosisScenario();
  sc.runs = {sc.runs.back()};  // fixed +30 °C, 9000 s
  sim::Trace data = sim::SimulateScenario(sc, sc.seed);
  sim::Run& run = data.runs.front();
  const int amb = run.Find("T_amb");
  run.names.erase(run.names.begin() + amb);
  run.columns.erase(run.columns.begin() + amb);
  sim::Trace shifted = data;
  for (size_t k = 0; k < run.size(); ++k) {
    if (std::min(3, static_cast<int>(run.t_s[k] / 2250.0)) % 2 == 0) continue;  // fitted
    for (const std::string ch : {"T1", "T2", "T3", "T4"}) shifted.runs.front().columns[run.Find(ch)][k] += 0.5;
  }
  DiagnoseOptions o;
  o.max_steps = 0;
  const Diagnosis a = Diagnose(data, test::DiagnosisScenario().gyro, o);
  const Diagnosis b = Diagnose(shifted, test::DiagnosisScenario().gyro, o);
  ASSERT_EQ(a.calibrated.count("T_amb:" + run.id), 1u);  // one ambient for the run
  // RMS(e + s) >= RMS(s) - RMS(e), s = 0.5 on every held-out mean.
  for (const std::string ch : {"T1", "T2", "T3", "T4"})
    EXPECT_GT(b.baseline.temperature_rms_C.at(ch), 0.5 - a.baseline.temperature_rms_C.at(ch)) << ch;
}

TEST(Diagnose, ReportsPosteriorCorrelationsOfTheKnobsGivenTheirCommonScale) {
  // Without conditioning on the common scale (which no temperature record fixes) every pair
  // would read +1. Given it, a node seen through its own sensor with a known ambient has its
  // time constant determined: its heat capacity and its one link to ambient move together.
  const sim::Scenario sc = test::DiagnosisScenario();
  DiagnoseOptions o;
  o.max_steps = 0;
  const Diagnosis d = Diagnose(sim::SimulateScenario(sc, sc.seed), sc.gyro, o);
  const Eigen::MatrixXd& r = d.knob_correlations;
  ASSERT_EQ(static_cast<size_t>(r.rows()), d.knob_names.size());
  ASSERT_EQ(r.rows(), r.cols());
  EXPECT_LT((r - r.transpose()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT((r.diagonal().array() - 1.0).abs().maxCoeff(), 1e-12);
  EXPECT_LE(r.cwiseAbs().maxCoeff(), 1.0 + 1e-12);
  EXPECT_LT(r.cwiseAbs().minCoeff(), 0.5);  // the scale direction is out
  auto at = [&](const std::string& name) {
    const auto it = std::find(d.knob_names.begin(), d.knob_names.end(), name);
    EXPECT_NE(it, d.knob_names.end()) << name;
    return static_cast<Eigen::Index>(it - d.knob_names.begin());
  };
  EXPECT_GT(r(at("C:cabinet"), at("G:cabinet-ambient")), 0.9);
}

TEST(Diagnose, TheWorkedExamplesHiddenRateIsNamed) {
  // scenarios/example-hidden-rate.toml: a rate on T1 of 0.04 °/h per °C/min, a ramp and a
  // discharge-power step, diagnosed against the gyro that made it (5 % prior). Two defects hid
  // it: the step was not in the CSV (so the baseline missed T2 by 0.13 °C and a 36 s lag on T2
  // was named), and a thermal candidate that failed the held-out test but outscored the rate
  // ended the search with "none".
  const sim::Scenario sc = io::LoadScenario(rlg::tools::SourcePath("scenarios/example-hidden-rate.toml"));
  const Diagnosis d = Diagnose(sim::SimulateScenario(sc, sc.seed), io::LoadGyro(rlg::tools::SourcePath("scenarios/gyros/default.toml")),
                               DiagnoseOptions{});
  ASSERT_FALSE(d.steps.empty()) << test::TopCandidates(d);
  const Candidate& got = d.steps.front().accepted;
  // Named by its own name: the gradients that come nearest score 2.1 lower and are listed
  // as ties (a rate is separable from them by this data).
  ASSERT_EQ(got.cause, "bias.temperature_rate") << test::TopCandidates(d);
  EXPECT_EQ(got.target, "T1");
  EXPECT_NEAR(got.parameters.at("k_dph_per_C_per_min"), 0.04, 0.2 * 0.04);
  // The baseline meets the temperatures at a few times the 100 s noise (0.4 mK), not 0.1 °C.
  for (const auto& [ch, rms] : d.baseline.temperature_rms_C) EXPECT_LT(rms, 0.01) << ch;
}

TEST(Diagnose, DataWithoutAHiddenEffectGivesNone) {
  const sim::Scenario sc = test::DiagnosisScenario();
  const Diagnosis d = Diagnose(sim::SimulateScenario(sc, sc.seed), sc.gyro, DiagnoseOptions{});
  EXPECT_TRUE(d.steps.empty()) << d.steps.front().accepted.cause << " " << d.steps.front().accepted.target;
  ASSERT_FALSE(d.first_candidates.empty());  // every candidate was still tried and ranked
}

TEST(Diagnose, ProgressNamesEachStageAndChangesNothing) {
  // 10 s samples: every stage still runs, on a tenth of the 1 s suite's samples.
  sim::Scenario sc = test::DiagnosisScenario();
  for (auto& run : sc.runs) run.sample_period_s = 10.0;
  const sim::Trace data = sim::SimulateScenario(sc, sc.seed);
  DiagnoseOptions quiet;
  quiet.max_steps = 1;
  DiagnoseOptions talking = quiet;
  std::vector<std::string> said;
  talking.progress = [&said](const std::string& what) { said.push_back(what); };
  const Diagnosis a = Diagnose(data, sc.gyro, quiet), b = Diagnose(data, sc.gyro, talking);
  EXPECT_EQ(DiagnosisJson(a).dump(), DiagnosisJson(b).dump());  // the callback only reports
  ASSERT_GE(said.size(), 4u);
  EXPECT_EQ(said.front(), "calibrating the nominal gyro");
  auto said_one = [&](const std::string& start) {
    return std::any_of(said.begin(), said.end(), [&](const std::string& s) { return s.rfind(start, 0) == 0; });
  };
  EXPECT_TRUE(said_one("null bootstrap: 40 replicates"));
  EXPECT_TRUE(said_one("step 1: screening "));
  EXPECT_TRUE(said_one("step 1: refitting thermal candidate 1 of "));
  EXPECT_TRUE(said_one("step 1: bias candidates"));
  EXPECT_EQ(said.back(), "residuals for the report");
}

}  // namespace
}  // namespace rlg::diagnosis
