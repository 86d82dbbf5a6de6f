// The default gyro reproduces the magnitudes the seed paper reports (PHYSICS.md, paper Table 2).

#include <gtest/gtest.h>

#include "model/pairs.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "sim/stats.h"
#include "tests/sim/test_helpers.h"

namespace rlg::sim {
namespace {

TEST(DefaultGyro, ReproducesThePapersTemperatureRiseAndBiasMagnitudes) {
  const Scenario sc = LoadScenario(test::SourcePath("scenarios/paper-fixed.toml"));
  ASSERT_EQ(sc.runs.size(), 10u);
  const Trace trace = SimulateScenario(sc, sc.seed);
  for (const sim::Run& r : trace.runs) {
    const auto& bias = r.Column("bias_dph");
    // Paper Table 2: run means 0.63...1.42 °/h; the band is 0.5...1.5 °/h.
    EXPECT_GT(Mean(bias), 0.5) << r.id;
    EXPECT_LT(Mean(bias), 1.5) << r.id;
    // "Before" stability, 1 sigma of 1 s samples with the thermal trend: 0.033...0.204 in the
    // paper; the band is 0.03...0.2 °/h.
    EXPECT_GT(StdDev(bias), 0.03) << r.id;
    EXPECT_LT(StdDev(bias), 0.2) << r.id;
    if (r.id == "fixed+0") {
      // Paper: at 0 °C T1 rose 1.5 °C and T2 2.5 °C over the test. The 0.2 °C band is about 10 %
      // of the rise: the paper's figures are read off plots.
      EXPECT_NEAR(r.Column("T1").back() - r.Column("T1").front(), 1.5, 0.2);
      EXPECT_NEAR(r.Column("T2").back() - r.Column("T2").front(), 2.5, 0.2);
    }
  }
}

TEST(DefaultGyro, SameSeedGivesTheSameTraceAndAnotherSeedDoesNot) {
  Scenario sc = LoadScenario(test::SourcePath("scenarios/paper-fixed.toml"));
  sc.runs.resize(2);
  for (auto& r : sc.runs) r.duration_s = 600;
  const Trace a = SimulateScenario(sc, 42), b = SimulateScenario(sc, 42), c = SimulateScenario(sc, 43);
  EXPECT_EQ(a.runs[1].columns, b.runs[1].columns);
  EXPECT_NE(a.runs[1].Column("bias_dph"), c.runs[1].Column("bias_dph"));
  EXPECT_NE(a.runs[0].Column("bias_dph"), a.runs[1].Column("bias_dph") ) << "runs share a random stream";
}

TEST(DefaultGyro, M1IsTheBestPairAsInThePapersTable1ForEverySeed) {
  // README "Why M1 wins": the physics, not a lucky seed. Four seeds keep the test quick; 16
  // were checked by hand (margins 2-14 % over the runner-up).
  const Scenario sc = LoadScenario(test::SourcePath("scenarios/paper-fixed.toml"));
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    const Trace trace = SimulateScenario(sc, seed);
    std::vector<sim::Run> averaged;
    for (const auto& r : trace.runs)
      if (r.id != "fixed+60") averaged.push_back(BlockMeans(r, 60.0));  // the paper's Table 1 data
    std::vector<const sim::Run*> runs;
    for (const auto& r : averaged) runs.push_back(&r);
    const auto scores = model::ScorePairs(runs, model::PaperCombinations(), model::FitOptions{});
    EXPECT_EQ(model::BestPair(scores).combination.name, "M1") << "seed " << seed;
  }
}

}  // namespace
}  // namespace rlg::sim
