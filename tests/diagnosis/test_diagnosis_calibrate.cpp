// Stage 2 of a diagnosis alone (diagnosis/network/calibrate.h, diagnosis::Calibrate): on data from the
// nominal gyro the calibration stays within its prior; on data from a gyro whose block-ambient
// conductance is 30 % low (7 prior sds at the file's 5 %), the knob moves toward the truth and
// is reported as a prior conflict. Invalid options are refused before any work.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <ostream>
#include <random>
#include <string>
#include <vector>

#include "diagnosis/diagnose.h"
#include "diagnosis/data/prepare.h"
#include "sim/errors.h"
#include "tests/diagnosis/hidden_effects.h"

namespace rlg::diagnosis {
namespace {

const KnobCalibration& Knob(const CalibrationSummary& s, const std::string& name) {
  for (const auto& k : s.knobs)
    if (k.name == name) return k;
  throw std::runtime_error("no knob " + name);
}

sim::Scenario ThreeRuns() {
  sim::Scenario sc = test::DiagnosisScenario();
  sc.runs.resize(3);  // enough to calibrate; keeps the test to seconds
  return sc;
}

TEST(Calibrate, OnDataFromTheNominalStaysWithinThePriorAndReportsItsWork) {
  const sim::Scenario sc = ThreeRuns();
  const CalibrationSummary s = Calibrate(sim::SimulateScenario(sc, sc.seed), sc.gyro, DiagnoseOptions{});
  EXPECT_TRUE(s.usable);
  EXPECT_GT(s.iterations, 0);
  EXPECT_LE(s.final_cost, s.initial_cost);
  EXPECT_DOUBLE_EQ(s.prior_sd, sc.gyro.calibration_uncertainty);
  ASSERT_EQ(static_cast<size_t>(s.covariance.rows()), s.knobs.size());
  EXPECT_TRUE(s.covariance.isApprox(s.covariance.transpose(), 1e-9));  // round-off of the pseudo-inverse
  for (const auto& k : s.knobs) {
    // Noise only: every knob within 3 prior sds (the conflict threshold); the determined ones
    // far closer, the undetermined ones held by the prior.
    EXPECT_LT(std::abs(k.shift_sigma), kPriorConflictSigma) << k.name;
    EXPECT_NEAR(k.shift_sigma, std::log(k.calibrated / k.nominal) / s.prior_sd, 1e-9) << k.name;
    EXPECT_GE(k.posterior_sd, 0.0);
  }
  EXPECT_TRUE(s.PriorConflicts().empty());
  // Nor together: a chi² p-value below 0.001 happens once in a thousand right nominals at most
  // (shifts are posterior means, smaller than the prior's draws).
  EXPECT_FALSE(s.JointConflict()) << s.JointShiftChi2();
}

TEST(Calibrate, ReportsAKnobFarFromItsNominalAsAPriorConflict) {
  sim::Scenario truth = ThreeRuns();
  const sim::GyroConfig nominal = truth.gyro;
  auto& links = truth.gyro.network.links;
  const int block = truth.gyro.network.FindNode("block");
  bool found = false;
  for (auto& l : links) {
    if ((l.a == block && l.b == sim::kAmbient) || (l.b == block && l.a == sim::kAmbient)) {
      l.conductance_W_per_K *= 0.7;  // ln 0.7 / 0.05 = -7.1 prior sds
      found = true;
    }
  }
  ASSERT_TRUE(found);
  const CalibrationSummary s = Calibrate(sim::SimulateScenario(truth, truth.seed), nominal, DiagnoseOptions{});
  ASSERT_TRUE(s.usable);
  const KnobCalibration& g = Knob(s, "G:block-ambient");
  // The prior pulls toward nominal, the data toward 0.7: the calibrated value lies between, and
  // beyond the conflict threshold.
  EXPECT_LT(g.calibrated, g.nominal);
  EXPECT_GT(g.calibrated, 0.6 * g.nominal);
  EXPECT_LT(g.shift_sigma, -kPriorConflictSigma);
  const auto conflicts = s.PriorConflicts();
  EXPECT_NE(std::find(conflicts.begin(), conflicts.end(), "G:block-ambient"), conflicts.end());
}

TEST(CalibrationSummary, JointShiftIsTheSumOfSquaredShiftsAgainstAChiSquareOfOneDegreePerKnob) {
  CalibrationSummary s;
  for (double shift : {3.0, 0.0, 0.0, 0.0}) s.knobs.push_back({"k", 1.0, 1.0, shift, 0.0});
  EXPECT_DOUBLE_EQ(s.JointShiftChi2(), 9.0);
  // Chi² with 4 degrees: P(X >= x) = exp(-x/2) (1 + x/2) in closed form.
  EXPECT_NEAR(s.JointShiftP(), std::exp(-4.5) * (1.0 + 4.5), 1e-12);
  EXPECT_FALSE(s.JointConflict());
  // Fourteen knobs at 2.1 sd, none beyond the single-knob threshold: chi² 61.7, p ~ 5e-8.
  CalibrationSummary many;
  for (int i = 0; i < 14; ++i) many.knobs.push_back({"k", 1.0, 1.0, i % 2 ? 2.1 : -2.1, 0.0});
  EXPECT_TRUE(many.PriorConflicts().empty());
  EXPECT_TRUE(many.JointConflict());
  EXPECT_LT(many.JointShiftP(), 1e-7);
  // No knobs: nothing to be in conflict.
  EXPECT_EQ(CalibrationSummary{}.JointShiftP(), 1.0);
}

TEST(Calibrate, LeavesASourceSwitchedOffInTheFileAlone) {
  // A gain of 0 (allowed by the gyro file) has no log to calibrate: the source gets no knob
  // instead of a prior centred at -infinity, and the calibration is usable.
  sim::Scenario sc = ThreeRuns();
  int off = -1;
  for (size_t s = 0; s < sc.gyro.network.sources.size(); ++s)
    if (sc.gyro.network.sources[s].name == "dither") off = static_cast<int>(s);
  ASSERT_GE(off, 0);
  sc.gyro.network.sources[static_cast<size_t>(off)].gain = 0.0;
  const sim::Trace data = sim::SimulateScenario(sc, sc.seed);
  const CalibrationSummary s = Calibrate(data, sc.gyro, DiagnoseOptions{});
  EXPECT_TRUE(s.usable);
  for (const auto& k : s.knobs) {
    EXPECT_NE(k.name, "gain:dither");
    EXPECT_TRUE(std::isfinite(k.shift_sigma)) << k.name;
  }
}

// Which runs of the diagnosis suite a start test takes: the first three (ramp 20-60 °C and the
// two 10/40 °C tables), or the two fixed chambers, one at 0 °C, where a start fitted in °C
// would put Ceres' relative derivative step at its 1.5e-8 floor (CurveStart, diagnosis/network/free.h).
struct StartCase {
  const char* name;
  std::vector<size_t> runs;
};

// What ctest shows of a case: its name.
void PrintTo(const StartCase& c, std::ostream* os) { *os << c.name; }

class NoisyAmbientStart : public ::testing::TestWithParam<StartCase> {};

TEST_P(NoisyAmbientStart, EachRunsStartIsFittedThroughCvode) {
  // The gyro powers on soaked at the true ambient; the chamber's log carries 2 mK of noise, so
  // the curve through it starts off by its first value's standard error, and the block keeps
  // that error for hours. The calibration fits each run's start (RunStart). Radiation from the
  // block makes the network nonlinear, so every simulation goes through CVODE, whose error the
  // numeric derivative's step must stay above (CurveStart, diagnosis/network/free.h).
  sim::Scenario sc = test::DiagnosisScenario();
  std::vector<sim::RunSpec> runs;
  for (size_t i : GetParam().runs) runs.push_back(sc.runs.at(i));
  sc.runs = runs;
  sc.gyro.network.radiation.push_back({sc.gyro.network.FindNode("block"), sim::kAmbient, 0.002});
  sim::Trace data = sim::SimulateScenario(sc, sc.seed);
  std::mt19937_64 rng(17);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::vector<double> truth_offset;  // true ambient at the first sample minus the curve's
  for (auto& run : data.runs) {
    std::vector<double>& amb = run.columns[static_cast<size_t>(run.Find("T_amb"))];
    const double true_start = amb.front();
    for (double& v : amb) v = std::round((v + noise(rng)) / 0.001) * 0.001;  // a 1 mK sensor
    // The curve diagnose drives the model with; the score-block noise only sets which jumps
    // are steps, and these ramps and tables have none.
    const sim::Profile curve = diagnosis::LoggedAmbient(run.t_s, amb, 1.0, 4e-4);
    truth_offset.push_back(true_start - curve.Value(run.t_s.front()));
  }
  const CalibrationSummary s = Calibrate(data, sc.gyro, DiagnoseOptions{});
  ASSERT_EQ(s.starts.size(), data.runs.size());
  double miss = 0.0, unmoved = 0.0;
  for (size_t r = 0; r < s.starts.size(); ++r) {
    const RunStart& st = s.starts[r];
    std::printf("%s: start offset %.3f mK, truth %.3f mK, prior sd %.3f mK\n", st.run.c_str(), 1e3 * st.offset_C,
                1e3 * truth_offset[r], 1e3 * st.prior_sd_C);
    EXPECT_GT(st.prior_sd_C, 0.0);
    // The block holds a start error for hours against 0.4 mK of noise on a 10 s block, so the
    // data fix it to a small part of its prior: within half the prior sd of the truth (an
    // unmoved start, at 0, is off by the truth's own offset, about one prior sd).
    EXPECT_NEAR(st.offset_C, truth_offset[r], 0.5 * st.prior_sd_C) << st.run;
    miss += std::pow(st.offset_C - truth_offset[r], 2);
    unmoved += std::pow(truth_offset[r], 2);
  }
  // Over the runs, the fitted starts' squared error is a small part of an unmoved start's (1):
  // measured 0.01 on the first three runs; 0.1 leaves room for the seed's luck, and a start
  // that did not move fails it.
  EXPECT_LT(miss, 0.1 * unmoved);
}

INSTANTIATE_TEST_SUITE_P(Calibrate, NoisyAmbientStart,
                         ::testing::Values(StartCase{"ramps_and_tables", {0, 1, 2}}, StartCase{"fixed_0C_and_30C", {3, 4}}),
                         [](const ::testing::TestParamInfo<StartCase>& i) { return std::string(i.param.name); });

TEST(Calibrate, RefusesInvalidOptionsBeforeAnyWork) {
  const sim::Scenario sc = ThreeRuns();
  DiagnoseOptions o;
  o.calibration.max_iterations = 0;
  sim::Trace empty;  // never read: the options are checked first
  EXPECT_THROW(Calibrate(empty, sc.gyro, o), InputError);
  EXPECT_THROW(Diagnose(empty, sc.gyro, o), InputError);
  o = DiagnoseOptions{};
  o.score_block_s = 5.0;  // shorter than the 10 s fit block
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("score_block_s"), std::string::npos) << why;
  o = DiagnoseOptions{};
  o.min_heldout_ratio = 0.9;
  EXPECT_FALSE(o.IsValid(&why));
  o = DiagnoseOptions{};
  o.lookahead = 0;  // 1 is the leader alone; 0 would compare nothing, not even the leader
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("lookahead"), std::string::npos) << why;
  EXPECT_TRUE(DiagnoseOptions{}.IsValid(&why)) << why;
}

}  // namespace
}  // namespace rlg::diagnosis
