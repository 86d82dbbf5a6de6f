// Stage 4 of a diagnosis alone (model/diagnosis_engine.h: Engine::FirstThermalCandidates,
// FirstBiasCandidates): on a calibration of the nominal gyro, the search over the catalog puts
// the hidden effect first and its refit or regression recovers the effect's size. Three runs of
// the diagnosis suite keep each test to seconds.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "model/diagnosis_engine.h"
#include "tests/model/hidden_effects.h"

namespace rlg::model::diagnosis {
namespace {

sim::Scenario ThreeRuns() {
  sim::Scenario sc = test::DiagnosisScenario();
  sc.runs.resize(3);
  return sc;
}

const Candidate& Best(const std::vector<Candidate>& c) {
  return *std::max_element(c.begin(), c.end(), [](const Candidate& a, const Candidate& b) { return a.score < b.score; });
}

TEST(ThermalSearch, ScreensAHiddenLinkFirstAndItsRefitRecoversTheConductance) {
  // A missing anode-cathode link of 0.01 W/K (the clear case of test_extended_gyro), in noisy
  // data. The screening orders candidates by their linearised gain: the link leads, is refitted
  // (kind "thermal", not screened only) and predicts the held-out fold better.
  sim::Scenario truth = ThreeRuns();
  sim::ApplyEffect({"thermal.missing_link", "anode-cathode", {{"conductance_W_per_K", 0.01}}}, truth.gyro);
  const sim::GyroConfig nominal = ThreeRuns().gyro;
  const sim::Trace data = sim::SimulateScenario(truth, truth.seed);  // the engine reads it in place
  const Engine engine(data, nominal, DiagnoseOptions{});
  const auto cal = engine.Calibrate();
  const std::vector<Candidate> c = engine.FirstThermalCandidates(cal);
  ASSERT_FALSE(c.empty());
  EXPECT_EQ(c.front().cause, "thermal.missing_link");
  EXPECT_EQ(CanonicalTarget(nominal, c.front().cause, c.front().target), CanonicalTarget(nominal, "thermal.missing_link", "anode-cathode"));
  EXPECT_EQ(c.front().kind, "thermal");
  // The candidate's refit (20 iterations of the effect alone, 30 jointly with the knobs) gets
  // the size's order only: 0.0058 W/K here. Accepted, the whole network is recalibrated with it
  // (Run), which brings it within the 20 % the Catalog tests check; a refit that finds the
  // optimum itself is the next issue's item 2. The band: a factor of 2 either way.
  const double g = c.front().parameters.at("conductance_W_per_K");
  EXPECT_GT(g, 0.005);
  EXPECT_LT(g, 0.02);
  EXPECT_GT(c.front().heldout_rms_ratio, 1.01);
  EXPECT_GE(c.front().score, 10.0);
  // Refits are limited to the best thermal_refits; the rest are screened only.
  const auto refitted = std::count_if(c.begin(), c.end(), [](const Candidate& x) { return x.kind.rfind("thermal (screened)", 0) != 0; });
  EXPECT_LE(refitted, DiagnoseOptions{}.thermal_refits);
}

TEST(BiasSearch, RegressesAHiddenRateWithTheBestScoreAndItsCoefficient) {
  // A rate term on the block (T1) of 0.3 °/h per °C/min in noise-free data: its regressor is
  // the simulator's own term, so the candidate fits the signal exactly (coefficient to 1 %:
  // the calibrated knobs move the node temperatures by ~1e-3 of their rates) and no other
  // candidate scores as high.
  sim::Scenario truth = test::Noiseless(ThreeRuns());
  sim::ApplyEffect({"bias.temperature_rate", "T1", {{"k_dph_per_C_per_min", 0.3}}}, truth.gyro);
  const sim::GyroConfig nominal = ThreeRuns().gyro;
  const sim::Trace data = sim::SimulateScenario(truth, 1);  // the engine reads it in place
  const Engine engine(data, nominal, DiagnoseOptions{});
  const std::vector<Candidate> c = engine.FirstBiasCandidates(engine.Calibrate());
  ASSERT_FALSE(c.empty());
  const Candidate& best = Best(c);
  EXPECT_EQ(best.cause, "bias.temperature_rate");
  EXPECT_EQ(CanonicalTarget(nominal, best.cause, best.target), CanonicalTarget(nominal, "bias.temperature_rate", "T1"));
  EXPECT_NEAR(best.parameters.at("k_dph_per_C_per_min"), 0.3, 0.003);
  EXPECT_GT(best.heldout_rms_ratio, 10.0);  // noise-free: the baseline misses by the whole term
  for (const auto& x : c) EXPECT_EQ(x.kind, "bias");
}

TEST(BiasSearch, IsEmptyWithoutBiasData) {
  sim::Scenario sc = ThreeRuns();
  sim::Trace data = sim::SimulateScenario(sc, sc.seed);
  for (auto& run : data.runs) {
    const int col = run.Find("bias_dph");
    ASSERT_GE(col, 0);
    run.columns.erase(run.columns.begin() + col);
    run.names.erase(run.names.begin() + col);
  }
  const Engine engine(data, sc.gyro, DiagnoseOptions{});
  EXPECT_TRUE(engine.FirstBiasCandidates(engine.Calibrate()).empty());
}

}  // namespace
}  // namespace rlg::model::diagnosis
