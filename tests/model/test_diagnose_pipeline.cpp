// Diagnosis end to end on clear hidden effects. Kept to the quicker ones (25-40 s each); a
// missing link (40 s) and radiation (3 min, CVODE in the calibration loop) pass too and run
// with the diagnosis_full label (tests/model/test_diagnose.cpp). (several times the strength of the 3-6x noise
// catalog test, which is labelled diagnosis_full: see README "Diagnosis status"). Blind: the
// data are simulated here; Diagnose sees the data and the nominal gyro only.

#include <gtest/gtest.h>

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
                      test::ClearCase{"bias.temperature_rate", "T1", "k_dph_per_C_per_min", {{"k_dph_per_C_per_min", 0.05}}}),
    [](const auto& info) { return test::TestName(info.param.effect); });

TEST(Diagnose, DataWithoutAHiddenEffectGivesNone) {
  const sim::Scenario sc = test::DiagnosisScenario();
  const Diagnosis d = Diagnose(sim::SimulateScenario(sc, sc.seed), sc.gyro, DiagnoseOptions{});
  EXPECT_TRUE(d.steps.empty()) << d.steps.front().accepted.cause << " " << d.steps.front().accepted.target;
  ASSERT_FALSE(d.first_candidates.empty());  // every candidate was still tried and ranked
}

}  // namespace
}  // namespace rlg::model
