// The diagnosis report (model/diagnosis_report.h) on hand-built Diagnosis records: no
// calibration runs, so every expected value is written here. Values the report copies from the
// record are compared exactly: a copy is the same double.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <string>

#include "model/diagnose.h"
#include "model/diagnosis_report.h"

namespace rlg::model {
namespace {

Candidate MakeCandidate(const std::string& cause, const std::string& target, const std::string& parameter, double value,
                        double score, double ratio, const std::string& kind) {
  Candidate c;
  c.cause = cause;
  c.target = target;
  c.parameters = {{parameter, value}};
  c.score = score;
  c.heldout_rms_ratio = ratio;
  c.kind = kind;
  return c;
}

Metrics MakeMetrics(double bias_rms_dph, double t1_rms_C, double t2_rms_C) {
  Metrics m;
  m.bias_rms_dph = bias_rms_dph;
  m.temperature_rms_C = {{"T1", t1_rms_C}, {"T2", t2_rms_C}};
  return m;
}

/// SPEC section 6's example: bias.temperature_rate on T1 accepted, hysteresis second. The
/// accepted candidate's own held-out ratio (3.2) differs from baseline / extended bias RMS
/// (0.0213 / 0.0061 = 3.49) so that a test can tell which one the headline took.
Diagnosis BiasDiagnosis() {
  Diagnosis d;
  d.has_bias = true;
  d.score_block_s = {100.0, 100.0};
  d.baseline = MakeMetrics(0.0213, 0.004, 0.006);
  d.extended = MakeMetrics(0.0061, 0.004, 0.006);
  const Candidate rate = MakeCandidate("bias.temperature_rate", "T1", "k_dph_per_C_per_min", 0.041, 412.0, 3.2, "bias");
  const Candidate hysteresis =
      MakeCandidate("bias.hysteresis", "T1", "k_heating_minus_cooling_dph_per_C", 0.002, 35.1, 1.12, "bias");
  DiagnosisStep step;
  step.accepted = rate;
  step.before = d.baseline;
  step.after = d.extended;
  step.compensated_stability_ratio = 1.8;
  step.candidates = {rate, hysteresis};
  step.notes = {"a step note"};
  d.steps = {step};
  d.first_candidates = {rate, hysteresis};
  d.calibrated = {{"C:block", 362.1}, {"G:block-ambient", 0.41}};
  d.identifiability = {"the data determine 2 of 3 combinations of the knobs"};
  d.knob_names = {"C:block", "G:block-ambient", "G:anode-block"};
  d.knob_correlations.resize(3, 3);
  d.knob_correlations << 1.0, -0.93, 0.85,  //
      -0.93, 1.0, 0.5,                      //
      0.85, 0.5, 1.0;
  d.ljung_box_p = {{"T1", 0.31}, {"bias_dph", 0.0021}};
  d.notes = {"a diagnosis note"};
  return d;
}

/// A thermal step first (a sensor lag, held-out ratio 1.13 on the temperatures), then a bias
/// step: the headline is the thermal step's own ratio.
Diagnosis ThermalFirstDiagnosis() {
  Diagnosis d = BiasDiagnosis();
  DiagnosisStep lag;
  lag.accepted = MakeCandidate("sensor.lag", "T2", "time_constant_s", 30.0, 520.0, 1.13, "thermal");
  lag.before = d.baseline;
  lag.after = MakeMetrics(0.0150, 0.004, 0.005);
  d.steps.insert(d.steps.begin(), lag);
  return d;
}

/// No significant candidate: the record the diagnosis leaves for "none".
Diagnosis NoneDiagnosis() {
  Diagnosis d = BiasDiagnosis();
  d.steps.clear();
  d.extended = Metrics{};  // never read for "none": extended repeats baseline
  return d;
}

TEST(DiagnosisJson, HasEverySpecKeyWithTheDiagnosisValues) {
  const Diagnosis d = BiasDiagnosis();
  const nlohmann::json j = DiagnosisJson(d);
  EXPECT_EQ(j.at("cause"), "bias.temperature_rate");
  EXPECT_EQ(j.at("target"), "T1");
  EXPECT_EQ(j.at("parameters").at("k_dph_per_C_per_min"), 0.041);
  EXPECT_EQ(j.at("baseline").at("bias_rms_dph"), 0.0213);
  EXPECT_EQ(j.at("baseline").at("temperature_rms_C").at("T2"), 0.006);
  EXPECT_EQ(j.at("extended").at("bias_rms_dph"), 0.0061);
  EXPECT_EQ(j.at("extended").at("temperature_rms_C").at("T1"), 0.004);
  // The same division in the same precision: the same double.
  EXPECT_EQ(j.at("gain").at("heldout_rms_ratio"), 0.0213 / 0.0061);
  EXPECT_EQ(j.at("gain").at("compensated_stability_ratio"), 1.8);
  ASSERT_EQ(j.at("candidates").size(), 2u);
  EXPECT_EQ(j.at("candidates")[0].at("cause"), "bias.temperature_rate");
  EXPECT_EQ(j.at("candidates")[0].at("score"), 412.0);
  EXPECT_EQ(j.at("candidates")[0].at("heldout_rms_ratio"), 3.2);
  EXPECT_EQ(j.at("candidates")[1].at("cause"), "bias.hysteresis");
  EXPECT_EQ(j.at("candidates")[1].at("target"), "T1");
  EXPECT_EQ(j.at("candidates")[1].at("score"), 35.1);
  EXPECT_EQ(j.at("candidates")[1].at("heldout_rms_ratio"), 1.12);
  EXPECT_EQ(j.at("candidates")[1].at("kind"), "bias");
  ASSERT_EQ(j.at("accepted").size(), 1u);
  const nlohmann::json& a = j.at("accepted")[0];
  EXPECT_EQ(a.at("cause"), "bias.temperature_rate");
  EXPECT_EQ(a.at("target"), "T1");
  EXPECT_EQ(a.at("parameters").at("k_dph_per_C_per_min"), 0.041);
  EXPECT_EQ(a.at("heldout_rms_ratio"), 3.2);
  EXPECT_EQ(a.at("compensated_stability_ratio"), 1.8);
  EXPECT_EQ(a.at("before").at("bias_rms_dph"), 0.0213);
  EXPECT_EQ(a.at("after").at("bias_rms_dph"), 0.0061);
  EXPECT_EQ(a.at("notes"), nlohmann::json({"a step note"}));
  EXPECT_EQ(j.at("calibrated").at("C:block"), 362.1);
  EXPECT_EQ(j.at("identifiability").size(), 1u);
  EXPECT_EQ(j.at("parameter_correlations").at("C:block").at("G:block-ambient"), -0.93);
  EXPECT_EQ(j.at("parameter_correlations").at("G:anode-block").at("G:anode-block"), 1.0);
  EXPECT_EQ(j.at("ljung_box_p").at("bias_dph"), 0.0021);
  EXPECT_EQ(j.at("score_block_s").at("min"), 100.0);
  EXPECT_EQ(j.at("score_block_s").at("max"), 100.0);
  EXPECT_EQ(j.at("notes"), nlohmann::json({"a diagnosis note"}));
}

TEST(DiagnosisJson, ThermalOnlyDataHasNoBiasRms) {
  Diagnosis d = ThermalFirstDiagnosis();
  d.has_bias = false;
  const nlohmann::json j = DiagnosisJson(d);
  EXPECT_FALSE(j.at("baseline").contains("bias_rms_dph"));
  EXPECT_FALSE(j.at("extended").contains("bias_rms_dph"));
  EXPECT_FALSE(j.at("accepted")[0].at("before").contains("bias_rms_dph"));
  EXPECT_TRUE(j.at("baseline").contains("temperature_rms_C"));
}

TEST(DiagnosisJson, NoneHasEmptyTargetAndParametersExtendedEqualToBaselineAndUnitRatios) {
  const nlohmann::json j = DiagnosisJson(NoneDiagnosis());
  EXPECT_EQ(j.at("cause"), "none");
  EXPECT_EQ(j.at("target"), "");
  EXPECT_EQ(j.at("parameters"), nlohmann::json::object());
  EXPECT_EQ(j.at("extended"), j.at("baseline"));
  EXPECT_EQ(j.at("gain").at("heldout_rms_ratio"), 1.0);
  EXPECT_EQ(j.at("gain").at("compensated_stability_ratio"), 1.0);
  EXPECT_EQ(j.at("accepted"), nlohmann::json::array());
  EXPECT_EQ(j.at("candidates").size(), 2u);  // every candidate tried is still listed
}

TEST(HeadlineRmsRatio, ABiasCauseFirstIsTheBiasRmsOfBaselineOverExtended) {
  EXPECT_EQ(HeadlineRmsRatio(BiasDiagnosis()), 0.0213 / 0.0061);  // same division: same double
}

TEST(HeadlineRmsRatio, AThermalCauseFirstIsThatStepsOwnHeldOutRatio) {
  EXPECT_EQ(HeadlineRmsRatio(ThermalFirstDiagnosis()), 1.13);
}

TEST(HeadlineRmsRatio, ABiasCauseWithoutAnExtendedBiasRmsFallsBackToTheStepsRatio) {
  Diagnosis d = BiasDiagnosis();
  d.extended.bias_rms_dph = 0.0;  // a ratio over 0 would be inf
  EXPECT_EQ(HeadlineRmsRatio(d), 3.2);
}

TEST(HeadlineRmsRatio, NoneIsOne) { EXPECT_EQ(HeadlineRmsRatio(NoneDiagnosis()), 1.0); }

TEST(CompensatedStabilityRatio, IsTheProductOverTheSteps) {
  Diagnosis d = ThermalFirstDiagnosis();
  d.steps[0].compensated_stability_ratio = 1.25;
  EXPECT_EQ(CompensatedStabilityRatio(d), 1.25 * 1.8);  // one multiplication: exact to the bit
}

TEST(ScoreBlockText, IsOneTimeOrARangeAsPrinted) {
  Diagnosis d;
  d.score_block_s = {100.0, 100.0};
  EXPECT_EQ(ScoreBlockText(d), "100 s");
  d.score_block_s = {99.0, 100.0};
  EXPECT_EQ(ScoreBlockText(d), "99-100 s");
  d.score_block_s = {99.99999999, 100.0};  // equal at three digits: one time
  EXPECT_EQ(ScoreBlockText(d), "100 s");
}

TEST(StrongCorrelations, ListsPairsAtLeastTheThresholdStrongestFirst) {
  const Diagnosis d = BiasDiagnosis();
  EXPECT_EQ(StrongCorrelations(d, 0.8, 5),
            (std::vector<std::string>{"C:block ~ G:block-ambient -0.93", "C:block ~ G:anode-block +0.85"}));
  EXPECT_EQ(StrongCorrelations(d, 0.8, 1), (std::vector<std::string>{"C:block ~ G:block-ambient -0.93"}));
  EXPECT_TRUE(StrongCorrelations(d, 0.95, 5).empty());
}

TEST(DiagnosisText, ShowsTheNamesAndNumbersOfTheDiagnosis) {
  DiagnosisTextOptions o;
  o.data_name = "data.csv";
  o.gyro_name = "gyro.toml";
  const std::string text = DiagnosisText(BiasDiagnosis(), o);
  for (const char* expected : {
           "Diagnosis of data.csv against gyro.toml (bias and temperature data)\n",
           "held-out RMS on 100 s means: T1 0.0040 °C T2 0.0060 °C, bias 0.0213 °/h\n",
           "  Ljung-Box p (bias_dph residuals, 10 lags): 0.0021\n",
           "  identifiability: the data determine 2 of 3 combinations of the knobs\n",
           "  posterior correlation: C:block ~ G:block-ambient -0.93\n",
           "  a diagnosis note\n",
           "  bias.temperature_rate    T1                 score      412.0  held-out RMS ratio 3.200\n",
           "  bias.hysteresis          T1                 score       35.1  held-out RMS ratio 1.120\n",
           "step 1: bias.temperature_rate on T1, k_dph_per_C_per_min = 0.041\n",
           "  held-out RMS ratio 3.200, compensated 100 s stability ratio 1.800\n",
           "  held-out RMS before -> after: T1 0.0040 -> 0.0040 °C T2 0.0060 -> 0.0060 °C, bias 0.0213 -> 0.0061 °/h\n",
           "  note: a step note\n",
       }) {
    EXPECT_NE(text.find(expected), std::string::npos) << "missing: " << expected << "\nin:\n" << text;
  }
  EXPECT_EQ(text.find("cause: none"), std::string::npos);
  EXPECT_EQ(text.back(), '\n');
}

TEST(DiagnosisText, SaysNoneAndListsAtMostTheCandidatesAsked) {
  DiagnosisTextOptions o;
  o.max_candidates = 1;
  const std::string text = DiagnosisText(NoneDiagnosis(), o);
  EXPECT_NE(text.find("\ncause: none (no candidate is significant)\n"), std::string::npos) << text;
  EXPECT_NE(text.find("bias.temperature_rate"), std::string::npos) << text;
  EXPECT_EQ(text.find("bias.hysteresis"), std::string::npos) << text;
  EXPECT_EQ(text.find("step 1"), std::string::npos) << text;
}

TEST(DiagnosisText, ThermalStepsHaveNoStabilityRatioAndThermalOnlyDataNoBias) {
  Diagnosis d = ThermalFirstDiagnosis();
  d.has_bias = false;
  const std::string text = DiagnosisText(d, {});
  EXPECT_NE(text.find("(thermal-only data)"), std::string::npos) << text;
  EXPECT_NE(text.find("step 1: sensor.lag on T2, time_constant_s = 30\n  held-out RMS ratio 1.130\n"), std::string::npos)
      << text;
  EXPECT_EQ(text.find("°/h"), std::string::npos) << text;
}

}  // namespace
}  // namespace rlg::model
