// Diagnosis end to end on clear hidden effects. Kept to the quick ones (5-11 s each); a
// missing link (40 s) and radiation (3 min, CVODE in the calibration loop) pass too and run
// with the diagnosis_full label (tests/model/test_diagnose.cpp). (several times the strength of the 3-6x noise
// catalog test, which is labelled diagnosis_full: see README "Diagnosis status"). Blind: the
// data are simulated here; Diagnose sees the data and the nominal gyro only.

#include <gtest/gtest.h>

#include "model/diagnose.h"
#include "tests/model/hidden_effects.h"

namespace rlg::model {
namespace {

struct Clear {
  std::string effect, target, checked;
  std::map<std::string, double> parameters;
};

Diagnosis DiagnoseHidden(const Clear& c) {
  sim::Scenario sc = test::DiagnosisScenario();
  if (c.effect != "none") sim::ApplyEffect({c.effect, c.target, c.parameters}, sc.gyro);
  const sim::Trace data = sim::SimulateScenario(sc, sc.seed);
  return Diagnose(data, test::DiagnosisScenario().gyro, DiagnoseOptions{});
}

class ClearEffect : public ::testing::TestWithParam<Clear> {};

TEST_P(ClearEffect, IsNamedWithItsTargetAndParameter) {
  const Clear& c = GetParam();
  const Diagnosis d = DiagnoseHidden(c);
  ASSERT_FALSE(d.steps.empty()) << "nothing accepted";
  const Candidate& got = d.steps.front().accepted;
  EXPECT_EQ(got.cause, c.effect);
  EXPECT_TRUE(test::SameTarget(test::DiagnosisScenario().gyro, c.effect, got.target, c.target)) << got.target;
  // 20 %: the bound for parameter recovery.
  EXPECT_NEAR(got.parameters.at(c.checked), c.parameters.at(c.checked), 0.2 * std::abs(c.parameters.at(c.checked)));
  EXPECT_GT(got.heldout_rms_ratio, 1.2);
}

INSTANTIATE_TEST_SUITE_P(
    Diagnose, ClearEffect,
    ::testing::Values(Clear{"sensor.lag", "T2", "time_constant_s", {{"time_constant_s", 30.0}}},
                      Clear{"thermal.missing_mass", "block-cabinet", "heat_capacity_J_per_K",
                            {{"heat_capacity_J_per_K", 200.0}, {"conductance_W_per_K", 0.05}}},
                      Clear{"bias.temperature_rate", "T1", "k_dph_per_C_per_min", {{"k_dph_per_C_per_min", 0.05}}}),
    [](const auto& info) {
      std::string n = info.param.effect;
      for (auto& ch : n)
        if (ch == '.') ch = '_';
      return n;
    });

TEST(Diagnose, DataWithoutAHiddenEffectGivesNone) {
  const Diagnosis d = DiagnoseHidden({"none", "", "", {}});
  EXPECT_TRUE(d.steps.empty()) << d.steps.front().accepted.cause << " " << d.steps.front().accepted.target;
  ASSERT_FALSE(d.first_candidates.empty());  // every candidate was still tried and ranked
}

}  // namespace
}  // namespace rlg::model
