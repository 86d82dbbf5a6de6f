// Stages 4 and 5 of a diagnosis alone (FirstThermalCandidates, network/thermal_search.h;
// FirstBiasCandidates, network/bias_search.h): on a calibration of the nominal gyro, the search over the catalog puts
// the hidden effect first and its refit or regression recovers the effect's size. Three runs of
// the diagnosis suite keep each test to seconds.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <ostream>
#include <string>

#include "diagnosis/catalog/effect_search.h"
#include "diagnosis/network/bias_search.h"
#include "diagnosis/network/calibrate.h"
#include "diagnosis/network/problem.h"
#include "diagnosis/network/thermal_search.h"
#include "sim/effect_registry.h"
#include "tests/diagnosis/hidden_effects.h"

namespace rlg::diagnosis {
namespace {

sim::Scenario ThreeRuns() {
  sim::Scenario sc = test::DiagnosisScenario();
  sc.runs.resize(3);
  return sc;
}

const Candidate& Best(const std::vector<Candidate>& c) {
  return *std::max_element(c.begin(), c.end(), [](const Candidate& a, const Candidate& b) { return a.score < b.score; });
}

TEST(InTimeFold, SplitsEachFitRunsBlocksIntoItsAlternateQuarters) {
  const sim::Scenario sc = ThreeRuns();
  const sim::Trace data = sim::SimulateScenario(sc, sc.seed);  // the problem reads it in place
  const Problem p = MakeProblem(data, sc.gyro, DiagnoseOptions{});
  const Problem a = InTimeFold(p, 0), b = InTimeFold(p, 1);
  for (int r : p.fit) {
    const auto& t = p.runs[r].run->t_s;
    const double quarter = (t.back() - t.front()) / 4.0;
    // Disjoint and together every block, each in a quarter of its fold.
    EXPECT_EQ(a.fit_blocks[r].size() + b.fit_blocks[r].size(), p.fit_blocks[r].size());
    for (const auto& [fold, parity] : {std::pair<const Problem*, int>{&a, 0}, {&b, 1}}) {
      ASSERT_EQ(fold->block_times[r].size(), fold->fit_blocks[r].size());
      ASSERT_EQ(fold->block_spans[r].size(), fold->fit_blocks[r].size());
      EXPECT_GT(fold->fit_blocks[r].size(), p.fit_blocks[r].size() / 3);  // about half each
      for (double tb : fold->block_times[r])
        EXPECT_EQ(std::min(3, static_cast<int>((tb - t.front()) / quarter)) % 2, parity) << tb;
    }
    for (const auto& block : a.fit_blocks[r])
      EXPECT_EQ(std::count(b.fit_blocks[r].begin(), b.fit_blocks[r].end(), block), 0);
  }
}

TEST(ThermalSearch, ScreensAHiddenLinkFirstAndItsRefitRecoversTheConductance) {
  // A missing anode-cathode link of 0.01 W/K (the clear case of test_extended_gyro), in noisy
  // data. The screening orders candidates by their linearised gain: the link leads, is refitted
  // (kind kThermal, not screened only) and predicts the held-out fold better.
  sim::Scenario truth = ThreeRuns();
  sim::ApplyEffect({"thermal.missing_link", "anode-cathode", {{"conductance_W_per_K", 0.01}}}, truth.gyro);
  const sim::GyroConfig nominal = ThreeRuns().gyro;
  const sim::Trace data = sim::SimulateScenario(truth, truth.seed);  // the problem reads it in place
  const Problem problem = MakeProblem(data, nominal, DiagnoseOptions{});
  const Calibration cal = Calibrate(problem, NominalModel(problem));
  const std::vector<Candidate> c = FirstThermalCandidates(problem, cal);
  ASSERT_FALSE(c.empty());
  EXPECT_EQ(c.front().cause, "thermal.missing_link");
  EXPECT_EQ(CanonicalTarget(nominal, c.front().cause, c.front().target), CanonicalTarget(nominal, "thermal.missing_link", "anode-cathode"));
  EXPECT_EQ(c.front().kind, CandidateKind::kThermal);
  // The candidate's refit (a log-space start search, then the effect alone and jointly with
  // the knobs) recovers the conductance: 0.01001 W/K measured. The band is the catalog tests'
  // 20 %.
  const double g = c.front().parameters.at("conductance_W_per_K");
  EXPECT_NEAR(g / 0.01, 1.0, 0.2) << g;
  EXPECT_GT(c.front().heldout_rms_ratio, 1.01);
  EXPECT_GE(c.front().score, 10.0);
  // Refits are limited to the best thermal_refits; the rest are screened only.
  const auto refitted = std::count_if(c.begin(), c.end(), [](const Candidate& x) { return x.kind != CandidateKind::kThermalScreened; });
  EXPECT_LE(refitted, DiagnoseOptions{}.thermal_refits);
}

// A hidden effect whose size is two decades from the catalog's start
// (ParameterSearch::start, where the screen evaluates it: link 0.005 W/K, lag 5 s, radiation
// 1e-3 m²): the screen, linearised at the start, and the refit must reach it. Measured with the
// refit's log-space multi-start (diagnosis/statistics/multistart.h) switched off, these clean cases still
// pass: the screen scales the size and the local fit walks in log units. The multi-start is for
// objectives with a local minimum on the way (its own tests, test_diagnosis_multistart.cpp).
// The cases lie above their starts: two decades below, each is below the noise of these runs
// (a 5e-5 W/K link block-cathode screens behind a sensor offset; a 0.05 s lag is outside the
// catalog's range). The mass's capacity is at its start; its conductance is the far one.
struct FarCase {
  const char* name;
  sim::EffectSpec truth;
  const char* parameter;
};

// What ctest shows of a case: its name.
void PrintTo(const FarCase& c, std::ostream* os) { *os << c.name; }

class FarFromStart : public ::testing::TestWithParam<FarCase> {};

TEST_P(FarFromStart, TheRefitReachesATruthTwoDecadesFromTheScreeningStart) {
  const FarCase& fc = GetParam();
  const double ratio = fc.truth.parameters.at(fc.parameter) / RequireSearch(fc.truth.name).Parameter(fc.parameter).start;
  ASSERT_GE(std::abs(std::log10(ratio)), 2.0) << "the case must lie two decades from the start";
  sim::Scenario truth = ThreeRuns();
  sim::ApplyEffect(fc.truth, truth.gyro);
  const sim::GyroConfig nominal = ThreeRuns().gyro;
  const sim::Trace data = sim::SimulateScenario(truth, truth.seed);
  const Problem problem = MakeProblem(data, nominal, DiagnoseOptions{});
  const std::vector<Candidate> c = FirstThermalCandidates(problem, Calibrate(problem, NominalModel(problem)));
  ASSERT_FALSE(c.empty());
  const Candidate& best = Best(c);
  EXPECT_EQ(best.cause, fc.truth.name);
  EXPECT_EQ(CanonicalTarget(nominal, best.cause, best.target), CanonicalTarget(nominal, fc.truth.name, fc.truth.target));
  EXPECT_EQ(best.kind, CandidateKind::kThermal);
  // Every parameter of the truth within 20 % (the catalog tests' bound; measured: 0.2 % or
  // better on these noisy runs).
  for (const auto& [name, want] : fc.truth.parameters) {
    ASSERT_TRUE(best.parameters.count(name)) << name;
    EXPECT_NEAR(best.parameters.at(name) / want, 1.0, 0.2) << name << ": fitted " << best.parameters.at(name) << ", truth " << want;
  }
}

INSTANTIATE_TEST_SUITE_P(
    Refit, FarFromStart,
    ::testing::Values(FarCase{"link_up", {"thermal.missing_link", "anode-cathode", {{"conductance_W_per_K", 0.5}}}, "conductance_W_per_K"},
                      FarCase{"mass_conductance_up", {"thermal.missing_mass", "anode-cathode", {{"heat_capacity_J_per_K", 100.0}, {"conductance_W_per_K", 2.0}}}, "conductance_W_per_K"},
                      FarCase{"lag_up", {"sensor.lag", "T2", {{"time_constant_s", 500.0}}}, "time_constant_s"},
                      FarCase{"radiation_up", {"thermal.radiation", "block-ambient", {{"emissivity_area_m2", 0.1}}}, "emissivity_area_m2"}),
    [](const ::testing::TestParamInfo<FarCase>& i) { return std::string(i.param.name); });

TEST(BiasSearch, RegressesAHiddenRateWithTheBestScoreAndItsCoefficient) {
  // A rate term on the block (T1) of 0.3 °/h per °C/min in noise-free data: its regressor is
  // the simulator's own term, so the candidate fits the signal exactly (coefficient to 1 %:
  // the calibrated knobs move the node temperatures by ~1e-3 of their rates) and no other
  // candidate scores as high.
  sim::Scenario truth = test::Noiseless(ThreeRuns());
  sim::ApplyEffect({"bias.temperature_rate", "T1", {{"k_dph_per_C_per_min", 0.3}}}, truth.gyro);
  const sim::GyroConfig nominal = ThreeRuns().gyro;
  const sim::Trace data = sim::SimulateScenario(truth, 1);  // the problem reads it in place
  const Problem problem = MakeProblem(data, nominal, DiagnoseOptions{});
  const std::vector<Candidate> c = FirstBiasCandidates(problem, Calibrate(problem, NominalModel(problem)));
  ASSERT_FALSE(c.empty());
  const Candidate& best = Best(c);
  EXPECT_EQ(best.cause, "bias.temperature_rate");
  EXPECT_EQ(CanonicalTarget(nominal, best.cause, best.target), CanonicalTarget(nominal, "bias.temperature_rate", "T1"));
  EXPECT_NEAR(best.parameters.at("k_dph_per_C_per_min"), 0.3, 0.003);
  EXPECT_GT(best.heldout_rms_ratio, 10.0);  // noise-free: the baseline misses by the whole term
  for (const auto& x : c) EXPECT_EQ(x.kind, CandidateKind::kBias);
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
  const Problem problem = MakeProblem(data, sc.gyro, DiagnoseOptions{});
  EXPECT_TRUE(FirstBiasCandidates(problem, Calibrate(problem, NominalModel(problem))).empty());
}

}  // namespace
}  // namespace rlg::diagnosis
