// Diagnosis end to end on clear hidden effects, several times the strength of the blind
// catalog test (tests/model/test_diagnose.cpp; README "Diagnosis status"), 2-11 s each.
// Blind: the data are simulated here; Diagnose sees the data and the nominal gyro only.

#include <gtest/gtest.h>

#include <cstdio>
#include <set>

#include "model/diagnose.h"
#include "tests/model/hidden_effects.h"

namespace rlg::model {
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
      // lambda ~ 200 at this size (README, "What diagnosis can tell apart").
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

TEST(Diagnose, DataWithoutAHiddenEffectGivesNone) {
  const sim::Scenario sc = test::DiagnosisScenario();
  const Diagnosis d = Diagnose(sim::SimulateScenario(sc, sc.seed), sc.gyro, DiagnoseOptions{});
  EXPECT_TRUE(d.steps.empty()) << d.steps.front().accepted.cause << " " << d.steps.front().accepted.target;
  ASSERT_FALSE(d.first_candidates.empty());  // every candidate was still tried and ranked
}

}  // namespace
}  // namespace rlg::model
