// Blind hidden-effect tests of `diagnose`: data simulated with one catalog effect on; the
// diagnosis gets the data and the nominal gyro only.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fmt/format.h>

#include "diagnosis/catalog/effect_search.h"
#include "diagnosis/diagnose.h"
#include "sim/effect_registry.h"
#include "tests/diagnosis/hidden_effects.h"

namespace rlg::diagnosis {
namespace {

class HiddenEffect : public ::testing::TestWithParam<std::string> {};

TEST_P(HiddenEffect, IsNamedWithItsTargetAndParameterAndGivesAHeldOutGain) {
  const std::string effect = GetParam();
  test::HiddenCase truth;
  const sim::Trace data = test::MakeHiddenCase(effect, 1000 + std::hash<std::string>{}(effect) % 1000, &truth);
  const sim::GyroConfig nominal = test::NominalForDiagnosis();
  const Diagnosis d = Diagnose(data, nominal, DiagnoseOptions{});
  const std::string cause = d.steps.empty() ? "none" : d.steps.front().accepted.cause;
  const std::string summary = fmt::format("truth {} {} strength {:.1f} {}", truth.effect, truth.target, truth.strength,
                                          effect == "none" ? 0.0 : truth.parameters.at(truth.checked));
  if (effect == "none") {
    ASSERT_EQ(cause, "none") << summary << test::TopCandidates(d);
    return;
  }
  ASSERT_NE(cause, "none") << summary << test::TopCandidates(d);
  const Candidate& got = d.steps.front().accepted;
  const test::Verdict v = test::Judge(nominal, truth, got.cause, got.target);
  std::printf("named %s %s: %s; %s = %g, expected %g\n", got.cause.c_str(), got.target.c_str(), v.why.c_str(),
              v.key.c_str(), got.parameters.count(v.key) ? got.parameters.at(v.key) : 0.0, v.expected);
  for (const auto& note : d.steps.front().notes) std::printf("  note: %s\n", note.c_str());
  test::ExpectTiesAreTheAmbiguousNote(d);  // the ties as data are the ones the note names
  ASSERT_TRUE(v.right) << got.cause << " " << got.target << " " << v.why << "; " << summary << test::TopCandidates(d);
  ASSERT_TRUE(got.parameters.count(v.key)) << v.key;
  // The catalog tests' bound: 20 %.
  EXPECT_NEAR(got.parameters.at(v.key), v.expected, 0.2 * std::abs(v.expected)) << v.key;
  EXPECT_GT(got.heldout_rms_ratio, 1.2);
}

INSTANTIATE_TEST_SUITE_P(Catalog, HiddenEffect,
                         ::testing::Values("none", "thermal.missing_mass", "thermal.missing_link", "thermal.power_drift",
                                           "thermal.radiation", "sensor.lag", "sensor.offset", "bias.temperature_rate",
                                           "bias.gradient", "bias.hysteresis", "bias.mode_hop"),
                         [](const auto& info) { return test::TestName(info.param); });

TEST(FalseAlarms, DataWithoutAnEffectGivesNoneForAtLeast95PercentOfSeeds) {
  const sim::Scenario sc = test::DiagnosisScenario();
  int none = 0;
  const int seeds = 20;
  for (int seed = 0; seed < seeds; ++seed) {
    const Diagnosis d = Diagnose(sim::SimulateScenario(sc, 5000 + seed), test::NominalForDiagnosis(), DiagnoseOptions{});
    if (d.steps.empty()) {
      ++none;
    } else {
      std::printf("seed %d: false alarm %s %s (score %.1f, held-out %.3f)\n", 5000 + seed,
                  d.steps.front().accepted.cause.c_str(), d.steps.front().accepted.target.c_str(),
                  d.steps.front().accepted.score, d.steps.front().accepted.heldout_rms_ratio);
    }
  }
  std::printf("none in %d of %d null datasets\n", none, seeds);
  EXPECT_GE(none, 19);  // >= 95 % of 20
}

TEST(ConfusionMatrix, AtLeast98OfHundredBlindCasesAreNamedRight) {
  // 9 drawn cases per catalog effect plus 10 without an effect: 100 in all. Case k is drawn
  // from seed base + 100 k; RLG_CONFUSION_SEED_BASE picks another set (default 20000).
  const char* base_env = std::getenv("RLG_CONFUSION_SEED_BASE");
  const uint64_t base = base_env ? std::stoull(base_env) : 20000;
  std::vector<std::string> effects = {"none"};
  for (const auto& e : test::HiddenCatalog()) effects.push_back(e.effect);
  std::map<std::string, std::map<std::string, int>> confusion;
  int right = 0, total = 0, twins = 0;  // twins: right answers that are not the truth's own name
  for (const auto& effect : effects) {
    const int cases = effect == "none" ? 10 : 9;
    for (int i = 0; i < cases; ++i) {
      test::HiddenCase truth;
      const sim::Trace data = test::MakeHiddenCase(effect, base + 100 * static_cast<uint64_t>(total), &truth);
      const sim::GyroConfig nominal = test::NominalForDiagnosis();
      const Diagnosis d = Diagnose(data, nominal, DiagnoseOptions{});
      const std::string cause = d.steps.empty() ? "none" : d.steps.front().accepted.cause;
      const std::string target = d.steps.empty() ? "" : d.steps.front().accepted.target;
      const test::Verdict v = test::Judge(nominal, truth, cause, target);
      ++confusion[effect][v.right ? effect : cause + (cause == effect ? " (target)" : "")];
      right += v.right;
      twins += v.right && v.why != "exact";
      ++total;
      std::printf("case %3d: %-22s %-16s -> %-22s %-16s %s %s\n", total, effect.c_str(), truth.target.c_str(), cause.c_str(),
                  target.c_str(), v.right ? "ok" : "WRONG", v.why.c_str());
      std::fflush(stdout);
    }
  }
  for (const auto& [truth, row] : confusion) {
    std::printf("%-22s:", truth.c_str());
    for (const auto& [got, n] : row) std::printf(" %s x%d", got.c_str(), n);
    std::printf("\n");
  }
  std::printf("accuracy %d / %d (seed base %llu); %d of them an answer the suite cannot tell from the truth\n", right,
              total, static_cast<unsigned long long>(base), twins);
  // The bound: 98 of 100 (100 on seed bases 20000 and 30000 when it was set).
  EXPECT_GE(right, 98);
}

/// The power `diagnose --power` computes is the power the search has, on the diagnosis suite:
/// on data without an effect it says at which size the cause on the target is named with 90 %
/// probability; at that size, on 10 seeds, it must be named at least 7 times (with power 0.9,
/// 6 or fewer in 1.3 % of runs), and at half the size it says it is detected at (a quarter of
/// the noncentrality: detected ~5 % of the time, plus the search's false-alarm rate of ~5 %)
/// the cause may be accepted at most 3 times (4 or more in ~1 % of runs), so that a power far
/// too cautious fails as one too bold does. (Probed when written, with the white-noise power of
/// one rival: named 10 of 10 at the size for both; at half the size 0 of 10 for the offset, and
/// at 0.7 of it 2 of 10 for the link, where 31 % was expected.)
void ExpectThePowerItComputes(const std::string& cause, const std::string& target) {
  const sim::Scenario sc = test::DiagnosisScenario();
  const sim::GyroConfig nominal = test::NominalForDiagnosis();
  DiagnoseOptions options;
  options.max_steps = 1;
  DiagnoseOptions with_power = options;
  with_power.power = true;
  const Diagnosis null = Diagnose(sim::SimulateScenario(sc, 7000), nominal, with_power);
  const EffectPower* power = nullptr;
  for (const auto& e : null.power)
    if (e.cause == cause && e.target == target) power = &e;
  ASSERT_NE(power, nullptr) << cause << " " << target;
  ASSERT_TRUE(std::isfinite(power->named)) << cause << " " << target;
  ASSERT_TRUE(power->named_plausible) << cause << " " << target;  // else the 90 % is not claimed
  auto count = [&](double size, bool target_too) {
    sim::Scenario at = sc;
    sim::ApplyEffect({cause, target, RequireSearch(cause).FromReported({{power->parameter, size}})}, at.gyro);
    int n = 0;
    for (int seed = 0; seed < 10; ++seed) {
      const Diagnosis d = Diagnose(sim::SimulateScenario(at, 7100 + static_cast<uint64_t>(seed)), nominal, options);
      const bool hit = !d.steps.empty() && d.steps.front().accepted.cause == cause &&
                       (!target_too || test::SameTarget(nominal, cause, d.steps.front().accepted.target, target));
      n += hit;
    }
    return n;
  };
  const int named = count(power->named, true), small = count(power->detected / 2.0, false);
  std::printf("%s %s: named above %s = %g (detected above %g, nearest %s %s, cosine %+.3f): named %d of 10 there, "
              "accepted %d of 10 at half the detected size\n",
              cause.c_str(), target.c_str(), power->parameter.c_str(), power->named, power->detected,
              power->rival_cause.c_str(), power->rival_target.c_str(), power->rival_cosine, named, small);
  EXPECT_GE(named, 7);
  EXPECT_LE(small, 3);
}

TEST(PowerBand, SensorOffsetIsNamedAtTheSizeItsPowerSays) { ExpectThePowerItComputes("sensor.offset", "T1"); }

TEST(PowerBand, MissingLinkIsNamedAtTheSizeItsPowerSays) {
  ExpectThePowerItComputes("thermal.missing_link", "cathode-ambient");
}

TEST(PowerBand, BiasHysteresisIsNamedAtTheSizeItsPowerSays) { ExpectThePowerItComputes("bias.hysteresis", "block"); }

}  // namespace
}  // namespace rlg::diagnosis
