// Blind hidden-effect tests of `diagnose`: data simulated with one catalog effect on; the
// diagnosis gets the data and the nominal gyro only.

#include <gtest/gtest.h>

#include <fmt/format.h>

#include "model/diagnose.h"
#include "tests/model/hidden_effects.h"

namespace rlg::model {
namespace {

class HiddenEffect : public ::testing::TestWithParam<std::string> {};

TEST_P(HiddenEffect, IsNamedWithItsTargetAndParameterAndGivesAHeldOutGain) {
  const std::string effect = GetParam();
  test::HiddenCase truth;
  const sim::Trace data = test::MakeHiddenCase(effect, 1000 + std::hash<std::string>{}(effect) % 1000, &truth);
  const sim::GyroConfig nominal = test::NominalForDiagnosis();
  const Diagnosis d = Diagnose(data, nominal, DiagnoseOptions{});
  const std::string cause = d.steps.empty() ? "none" : d.steps.front().accepted.cause;
  ASSERT_EQ(cause, effect) << fmt::format("truth {} {} strength {:.1f}", truth.effect, truth.target, truth.strength);
  if (effect == "none") return;
  const Candidate& got = d.steps.front().accepted;
  EXPECT_TRUE(test::SameTarget(nominal, effect, got.target, truth.target)) << got.target << " vs " << truth.target;
  std::string key = truth.checked;
  double expected = truth.parameters.at(key);
  if (effect == "bias.hysteresis") {
    key = "k_heating_minus_cooling_dph_per_C";  // the identifiable combination
    expected = truth.parameters.at("k_heating_dph_per_C") - truth.parameters.at("k_cooling_dph_per_C");
  }
  ASSERT_TRUE(got.parameters.count(key)) << key;
  // The bound: 20 %.
  EXPECT_NEAR(got.parameters.at(key), expected, 0.2 * std::abs(expected)) << key;
  EXPECT_GT(got.heldout_rms_ratio, 1.2);
}

INSTANTIATE_TEST_SUITE_P(Catalog, HiddenEffect,
                         ::testing::Values("none", "thermal.missing_mass", "thermal.missing_link", "thermal.power_drift",
                                           "thermal.radiation", "sensor.lag", "sensor.offset", "bias.temperature_rate",
                                           "bias.gradient", "bias.hysteresis", "bias.mode_hop"),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (auto& ch : n)
                             if (ch == '.') ch = '_';
                           return n;
                         });

// Clear (strong) effects whose diagnosis is slow: CVODE in the calibration loop.
struct SlowClear {
  std::string effect, target, checked;
  std::map<std::string, double> parameters;
};
class SlowClearEffect : public ::testing::TestWithParam<SlowClear> {};

TEST_P(SlowClearEffect, IsNamedWithItsTargetAndParameter) {
  const SlowClear& c = GetParam();
  sim::Scenario sc = test::DiagnosisScenario();
  sim::ApplyEffect({c.effect, c.target, c.parameters}, sc.gyro);
  const Diagnosis d = Diagnose(sim::SimulateScenario(sc, sc.seed), test::DiagnosisScenario().gyro, DiagnoseOptions{});
  ASSERT_FALSE(d.steps.empty());
  const Candidate& got = d.steps.front().accepted;
  EXPECT_EQ(got.cause, c.effect);
  EXPECT_TRUE(test::SameTarget(test::DiagnosisScenario().gyro, c.effect, got.target, c.target)) << got.target;
  EXPECT_NEAR(got.parameters.at(c.checked), c.parameters.at(c.checked), 0.2 * std::abs(c.parameters.at(c.checked)));
  EXPECT_GT(got.heldout_rms_ratio, 1.2);
}

INSTANTIATE_TEST_SUITE_P(
    Diagnose, SlowClearEffect,
    ::testing::Values(SlowClear{"thermal.missing_link", "anode-cathode", "conductance_W_per_K", {{"conductance_W_per_K", 0.01}}},
                      SlowClear{"thermal.radiation", "block-ambient", "emissivity_area_m2", {{"emissivity_area_m2", 0.002}}}),
    [](const auto& info) {
      std::string n = info.param.effect;
      for (auto& ch : n)
        if (ch == '.') ch = '_';
      return n;
    });

}  // namespace
}  // namespace rlg::model
