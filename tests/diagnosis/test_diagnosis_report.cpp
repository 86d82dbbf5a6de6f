// The diagnosis report (diagnosis/report.h) on hand-built Diagnosis records: no
// calibration runs, so every expected value is written here. Values the report copies from the
// record are compared exactly: a copy is the same double.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "diagnosis/diagnose.h"
#include "diagnosis/report.h"

namespace rlg::diagnosis {
namespace {

Candidate MakeCandidate(const std::string& cause, const std::string& target, const std::string& parameter, double value,
                        double score, double ratio, CandidateKind kind) {
  Candidate c;
  c.cause = cause;
  c.target = target;
  c.parameters = {{parameter, value}};
  c.score = score;
  c.heldout_rms_ratio = ratio;
  c.heldout_gain = 100.0 * std::log(ratio);  // as if 100 held-out residuals: 116.3 for 3.2
  c.kind = kind;
  return c;
}

Metrics MakeMetrics(double bias_rms_dph, double t1_rms_C, double t2_rms_C) {
  Metrics m;
  m.bias_rms_dph = bias_rms_dph;
  m.temperature_rms_C = {{"T1", t1_rms_C}, {"T2", t2_rms_C}};
  return m;
}

/// docs/diagnosis.md's example: bias.temperature_rate on T1 accepted, hysteresis second. The
/// accepted candidate's own held-out ratio (3.2) differs from baseline / extended bias RMS
/// (0.0213 / 0.0061 = 3.49) so that a test can tell which one the headline took.
Diagnosis BiasDiagnosis() {
  Diagnosis d;
  d.has_bias = true;
  d.score_block_s = {100.0, 100.0};
  d.baseline = MakeMetrics(0.0213, 0.004, 0.006);
  d.extended = MakeMetrics(0.0061, 0.004, 0.006);
  const Candidate rate = MakeCandidate("bias.temperature_rate", "T1", "k_dph_per_C_per_min", 0.041, 412.0, 3.2, CandidateKind::kBias);
  const Candidate hysteresis =
      MakeCandidate("bias.hysteresis", "T1", "k_heating_minus_cooling_dph_per_C", 0.002, 35.1, 1.12, CandidateKind::kBias);
  DiagnosisStep step;
  step.accepted = rate;
  step.before = d.baseline;
  step.after = d.extended;
  step.compensated_stability_ratio = 1.8;
  step.threshold = 31.5;
  step.candidates = {rate, hysteresis};
  step.notes = {"a step note"};
  step.ties = {{"bias.gradient", "block-cabinet", -0.25, true, -1.5, true}, {"bias.hysteresis", "T1", 16.5, false, 12.0, false}};
  d.steps = {step};
  d.first_candidates = {rate, hysteresis};
  d.calibrated = {{"C:block", 362.1}, {"G:block-ambient", 0.41}};
  d.identifiability.knobs = 3;
  d.identifiability.determined = 2;
  d.identifiability.prior_sd = 0.05;
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
  lag.accepted = MakeCandidate("sensor.lag", "T2", "time_constant_s", 30.0, 520.0, 1.13, CandidateKind::kThermal);
  lag.before = d.baseline;
  lag.after = MakeMetrics(0.0150, 0.004, 0.005);
  lag.threshold = 44.2;
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
  EXPECT_EQ(a.at("threshold"), 31.5);
  EXPECT_EQ(a.at("before").at("bias_rms_dph"), 0.0213);
  EXPECT_EQ(a.at("after").at("bias_rms_dph"), 0.0061);
  EXPECT_EQ(a.at("notes"), nlohmann::json({"a step note"}));
  ASSERT_EQ(a.at("ties").size(), 2u);
  EXPECT_EQ(a.at("ties")[0], nlohmann::json({{"cause", "bias.gradient"},
                                             {"target", "block-cabinet"},
                                             {"score_difference", -0.25},
                                             {"heldout_difference", -1.5},
                                             {"ambiguous", true},
                                             {"plausible", true}}));
  EXPECT_EQ(a.at("ties")[1].at("score_difference"), 16.5);
  EXPECT_EQ(a.at("ties")[1].at("heldout_difference"), 12.0);
  EXPECT_EQ(a.at("ties")[1].at("ambiguous"), false);
  EXPECT_EQ(a.at("ties")[1].at("plausible"), false);
  EXPECT_NEAR(a.at("heldout_gain").get<double>(), 100.0 * std::log(3.2), 1e-12);
  // The answer is the set the data cannot split: the tie within the band, not the stand-in beyond it.
  EXPECT_EQ(j.at("ambiguous_with"), nlohmann::json::array({{{"cause", "bias.gradient"},
                                                             {"target", "block-cabinet"},
                                                             {"score_difference", -0.25},
                                                             {"heldout_difference", -1.5}}}));
  EXPECT_EQ(j.at("calibrated").at("C:block"), 362.1);
  EXPECT_EQ(j.at("identifiability").size(), 1u);
  EXPECT_EQ(j.at("parameter_correlations").at("C:block").at("G:block-ambient"), -0.93);
  EXPECT_EQ(j.at("parameter_correlations").at("G:anode-block").at("G:anode-block"), 1.0);
  EXPECT_EQ(j.at("ljung_box_p").at("bias_dph"), 0.0021);
  EXPECT_EQ(j.at("score_block_s").at("min"), 100.0);
  EXPECT_EQ(j.at("score_block_s").at("max"), 100.0);
  EXPECT_EQ(j.at("notes"), nlohmann::json({"a diagnosis note"}));
}

TEST(DiagnosisJson, AnAcceptedEffectOutsideItsPlausibleRangeIsMarkedAndTheTextSaysItIsAStandIn) {
  Diagnosis d = ThermalFirstDiagnosis();
  // A lag of 30 s on T2 is plausible (HasEverySpecKey... has a rate of 0.041 °/h per °C/min);
  // a missing mass of 1e51 J/K, what a refit that runs off to a heat sink reports, is not.
  EXPECT_EQ(DiagnosisJson(d).at("accepted")[0].at("plausible"), true);
  EXPECT_EQ(DiagnosisJson(d).at("accepted")[1].at("plausible"), true);
  EXPECT_FALSE(DiagnosisJson(d).at("accepted")[0].contains("implausible"));
  d.steps.front().accepted = MakeCandidate("thermal.missing_mass", "block-cabinet", "heat_capacity_J_per_K", 2.4e51, 99.0, 2.4, CandidateKind::kThermal);
  d.steps.front().accepted.parameters["conductance_W_per_K"] = 1.5e-4;
  const nlohmann::json a = DiagnosisJson(d).at("accepted")[0];
  EXPECT_EQ(a.at("plausible"), false);
  ASSERT_EQ(a.at("implausible").size(), 1u);  // the conductance is plausible
  EXPECT_EQ(a.at("implausible")[0].at("parameter"), "heat_capacity_J_per_K");
  EXPECT_EQ(a.at("implausible")[0].at("value"), 2.4e51);
  EXPECT_EQ(a.at("implausible")[0].at("unit"), "J/K");
  const double lo = a.at("implausible")[0].at("plausible_range")[0], hi = a.at("implausible")[0].at("plausible_range")[1];
  EXPECT_LT(lo, hi);
  EXPECT_LT(hi, 2.4e51);
  EXPECT_NE(a.at("implausible")[0].at("source").get<std::string>().find("[est]"), std::string::npos);
  const std::string text = DiagnosisText(d, DiagnosisTextOptions{});
  EXPECT_NE(text.find("stand-in: thermal.missing_mass was fitted at an implausible size, heat_capacity_J_per_K = 2.4e+51 J/K"),
            std::string::npos)
      << text;
  // A hysteresis is reported as the difference of its coefficients; the range is checked on
  // what it applies (k_heating = the difference, k_cooling = 0).
  d.steps.front().accepted = MakeCandidate("bias.hysteresis", "block", "k_heating_minus_cooling_dph_per_C", 0.005, 50.0, 1.3, CandidateKind::kBias);
  EXPECT_EQ(DiagnosisJson(d).at("accepted")[0].at("plausible"), true);
  d.steps.front().accepted.parameters["k_heating_minus_cooling_dph_per_C"] = 1e3;  // 1000 °/h per °C
  EXPECT_EQ(DiagnosisJson(d).at("accepted")[0].at("plausible"), false);
  EXPECT_EQ(DiagnosisJson(d).at("accepted")[0].at("implausible")[0].at("parameter"), "k_heating_dph_per_C");
}

TEST(DiagnosisJson, AThermalStepListsTheKnobsItMovedAndTheCalibrationItsJointShift) {
  Diagnosis d = ThermalFirstDiagnosis();
  EXPECT_EQ(DiagnosisJson(d).at("accepted")[0].at("knobs"), nlohmann::json::array());
  d.steps.front().knob_shifts = {{"G:block-ambient", -11.2, -0.4}, {"gain:dither", 4.5, 0.3}};
  const nlohmann::json k = DiagnosisJson(d).at("accepted")[0].at("knobs");
  ASSERT_EQ(k.size(), 2u);
  EXPECT_EQ(k[0].at("name"), "G:block-ambient");
  EXPECT_EQ(k[0].at("shift_sigma_before"), -11.2);
  EXPECT_EQ(k[0].at("shift_sigma_after"), -0.4);
  const std::string text = DiagnosisText(d, DiagnosisTextOptions{});
  EXPECT_NE(text.find("knobs (shift from nominal in prior sds, before -> after this step): G:block-ambient -11.2 -> -0.4 sd, "
                      "gain:dither +4.5 -> +0.3 sd"),
            std::string::npos)
      << text;
  d.calibration.knobs = {{"C:block", 1.0, 1.0, 2.0, 0.1}, {"C:anode", 1.0, 1.0, -2.0, 0.1}};
  const nlohmann::json js = DiagnosisJson(d).at("calibration").at("joint_shift");
  EXPECT_EQ(js.at("chi2"), 8.0);
  EXPECT_EQ(js.at("knobs"), 2);
  EXPECT_NEAR(js.at("p").get<double>(), std::exp(-4.0), 1e-12);  // chi² with 2 degrees: exp(-x/2)
  EXPECT_EQ(js.at("conflict"), false);
}

TEST(DiagnosisJson, NullBootstrapHasTheThresholdAndEveryReplicateScoreWithNullWhereNonePassed) {
  Diagnosis d = BiasDiagnosis();
  d.null_bootstrap.threshold = 31.5;
  d.null_bootstrap.replicate_scores = {12.0, -std::numeric_limits<double>::infinity(), 31.5};
  d.null_bootstrap.replicates = 3;
  const nlohmann::json j = DiagnosisJson(d);
  EXPECT_EQ(j.at("null_bootstrap").at("threshold"), 31.5);
  const nlohmann::json& scores = j.at("null_bootstrap").at("replicate_scores");
  ASSERT_EQ(scores.size(), 3u);
  EXPECT_EQ(scores[0], 12.0);
  EXPECT_EQ(scores[2], 31.5);
  // -infinity (no candidate passed the held-out test) is no JSON number: dumped as null.
  EXPECT_EQ(nlohmann::json::parse(j.dump()).at("null_bootstrap").at("replicate_scores")[1], nullptr);
}

TEST(DiagnosisJson, ThermalNullBootstrapHasItsOwnThresholdAndReplicates) {
  Diagnosis d = BiasDiagnosis();
  d.null_bootstrap.threshold = 31.5;
  d.thermal_null_bootstrap.threshold = 44.2;
  d.thermal_null_bootstrap.replicate_scores = {-3.0, 44.2};
  d.thermal_null_bootstrap.replicates = 2;
  d.thermal_null_bootstrap.data_score = 7.5;
  const nlohmann::json j = DiagnosisJson(d);
  EXPECT_EQ(j.at("thermal_null_bootstrap").at("threshold"), 44.2);
  EXPECT_EQ(j.at("thermal_null_bootstrap").at("data_score"), 7.5);
  EXPECT_EQ(j.at("thermal_null_bootstrap").at("replicate_scores"), nlohmann::json({-3.0, 44.2}));
  EXPECT_EQ(j.at("null_bootstrap").at("threshold"), 31.5);
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
           "  identifiability: the data determine 2 of 3 combinations of the knobs (posterior sd below half the prior's "
           "0.05 in log units)\n",
           "  posterior correlation: C:block ~ G:block-ambient -0.93\n",
           "  a diagnosis note\n",
           "  bias.temperature_rate    T1                 score      412.0  held-out gain    116.3  RMS ratio 3.200\n",
           "  bias.hysteresis          T1                 score       35.1  held-out gain     11.3  RMS ratio 1.120\n",
           "step 1: bias.temperature_rate on T1, k_dph_per_C_per_min = 0.041\n",
           "  score 412.0 (needed 31.5), held-out gain 116.3, held-out RMS ratio 3.200, compensated 100 s stability ratio 1.800\n",
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

TEST(DiagnosisText, EndsWithAVerdictNamingWhatWasAddedAndWhatIsLeft) {
  auto last_line = [](const std::string& text) {
    const size_t end = text.find_last_not_of('\n');
    return text.substr(text.rfind('\n', end) + 1, end - text.rfind('\n', end));
  };
  EXPECT_EQ(last_line(DiagnosisText(NoneDiagnosis(), {})),
            "verdict: no effect added: the calibrated nominal model leaves nothing well above the noise unexplained");
  Diagnosis d = ThermalFirstDiagnosis();
  EXPECT_EQ(last_line(DiagnosisText(d, {})),
            "verdict: 2 effects added (sensor.lag on T2, then bias.temperature_rate on T1 or, not told apart by these "
            "data, bias.gradient on block-cabinet); nothing well above the noise is left unexplained");  // the tie within
                                                                                                 // the band, not the stand-in
  d.steps.erase(d.steps.begin());
  d.steps.front().accepted.parameters["k_dph_per_C_per_min"] = 1e3;  // beyond the catalog's range: a stand-in
  d.unexplained = {diagnosis::Unexplained{"T1", "run-a", 4.2, 1e-3, 1e-6, {100.0, 900.0}, {}}};
  EXPECT_EQ(last_line(DiagnosisText(d, {})),
            "verdict: one effect added (bias.temperature_rate on T1 (a stand-in, outside its plausible range) or, not "
            "told apart by these data, bias.gradient on block-cabinet); the model still misses the data where no "
            "catalog effect explains it (see unexplained)");
  d.steps.clear();
  EXPECT_EQ(DiagnosisVerdict(d),
            "no catalog effect is significant; the model still misses the data where no catalog effect explains it (see "
            "unexplained)");
}

TEST(DiagnosisText, WithoutANetworkNoAllClearOverThreeTimesTheNoise) {
  // A named cause and nothing in `unexplained` once ended "nothing that moves with the
  // temperature is left unexplained" over a residual 42 times the noise.
  DiagnosisWithoutNetwork d;
  static_cast<SearchRecord&>(d) = NoneDiagnosis();
  d.polynomial_order = 1;
  d.polynomial_channel = "T1";
  d.score_block_s = {100.0, 100.0};
  d.bias_left = BiasLeft{0.0845, 0.002, "heating T1", -0.06, 0.97, 200};
  const std::string none = DiagnosisVerdict(d);
  EXPECT_EQ(none.rfind("unexplained: no candidate is significant against the best polynomial in T1 (order 1)", 0), 0u) << none;
  EXPECT_NE(none.find("0.0845 °/h RMS on 100 s means, 42.2x the white noise of such a mean (0.002 °/h)"),
            std::string::npos) << none;
  EXPECT_NE(none.find("with heating T1, is r = -0.06, no more than slow noise reaches (0.97 on 200 replicates"),
            std::string::npos) << none;
  d.steps = ThermalFirstDiagnosis().steps;
  d.steps.erase(d.steps.begin());
  const std::string named = DiagnosisVerdict(d);
  EXPECT_NE(named.find(" misses bias.temperature_rate on T1 "), std::string::npos) << named;
  EXPECT_NE(named.find("; unexplained: the held-out residual is 0.0845 °/h"), std::string::npos) << named;
  EXPECT_EQ(named.find("nothing that moves"), std::string::npos) << named;
  EXPECT_EQ(named.find("at the noise"), std::string::npos) << named;
  // At three times the noise or below: the all-clear, with the size.
  d.bias_left->rms_dph = 0.006;
  EXPECT_NE(DiagnosisVerdict(d).find("; what is left is at the noise (the held-out residual is 0.006 °/h RMS on 100 s "
                                     "means, 3.0x the white noise"),
            std::string::npos) << DiagnosisVerdict(d);
  d.steps.clear();
  EXPECT_NE(DiagnosisVerdict(d).find("none: no candidate is significant"), std::string::npos);
  EXPECT_NE(DiagnosisVerdict(d).find("and its residual is at the noise"), std::string::npos);
  // The text's `left:` line and the JSON's `left`.
  EXPECT_NE(DiagnosisText(d, {}).find("\nleft: the held-out residual is 0.006 °/h"), std::string::npos);
  const auto j = DiagnosisJson(d);
  EXPECT_TRUE(j["left"]["at_noise"].get<bool>());
  EXPECT_NEAR(j["left"]["rms_over_noise"].get<double>(), 3.0, 1e-12);  // 0.006 / 0.002, to round-off
  d.bias_left->rms_dph = 0.0061;
  EXPECT_FALSE(DiagnosisJson(d)["left"]["at_noise"].get<bool>());
  EXPECT_EQ(DiagnosisVerdict(d).rfind("unexplained: ", 0), 0u);
  // Against a gyro: no `left`.
  EXPECT_FALSE(DiagnosisJson(NoneDiagnosis()).contains("left"));
}

TEST(DiagnosisText, ThermalStepsHaveNoStabilityRatioAndThermalOnlyDataNoBias) {
  Diagnosis d = ThermalFirstDiagnosis();
  d.has_bias = false;
  const std::string text = DiagnosisText(d, {});
  EXPECT_NE(text.find("(thermal-only data)"), std::string::npos) << text;
  EXPECT_NE(text.find("step 1: sensor.lag on T2, time_constant_s = 30\n  score 520.0 (needed 44.2), held-out gain 12.2, held-out RMS ratio 1.130\n"), std::string::npos)
      << text;
  EXPECT_EQ(text.find("°/h"), std::string::npos) << text;
}

// ---- residuals.csv and the figures' data ----

// A linear ramp T = 20 + 0.03 t (°C, t in s): dT/dt = 1.8 °C/min at every block. Central and
// one-sided differences of a line are its slope whatever the spacing; the only error is the
// round-off of T (~4e-15 °C at 21 °C) over a time step of >= 5 s, x 60: ~5e-14 °C/min. 1e-12
// leaves a factor 20 for the few operations.
constexpr double kRampRate_C_per_s = 0.03;
constexpr double kRampRate_C_per_min = 60.0 * kRampRate_C_per_s;
constexpr double kRateRoundOff_C_per_min = 1e-12;

double Ramp(double t_s) { return 20.0 + kRampRate_C_per_s * t_s; }

/// Residual traces of two runs at 10 s fit blocks: run "a" (25 blocks) has T1 on the ramp and a
/// bias; run "b" (12 blocks) has T1 only. Residuals: baseline 0.1 °C, extended 0.01 * k.
Diagnosis TraceDiagnosis() {
  Diagnosis d = BiasDiagnosis();
  d.score_block_s = {100.0, 100.0};
  for (const auto& [id, blocks, bias] : {std::tuple<std::string, size_t, bool>{"a", 25, true}, {"b", 12, false}}) {
    ResidualTrace tr;
    tr.run = id;
    for (size_t k = 0; k < blocks; ++k) {
      const double t = 5.0 + 10.0 * static_cast<double>(k);
      tr.t_s.push_back(t);
      tr.measured["T1"].push_back(Ramp(t));
      tr.baseline["T1"].push_back(0.1);
      tr.extended["T1"].push_back(0.01 * static_cast<double>(k));
      if (bias) {
        tr.measured["bias_dph"].push_back(0.5 + 1e-3 * t);
        tr.baseline["bias_dph"].push_back(0.02);
        tr.extended["bias_dph"].push_back(-0.002);
      }
    }
    d.residuals.push_back(tr);
  }
  return d;
}

TEST(RatePerMinute, IsTheSlopeOfALinearRampAtEveryPointWhateverTheSpacing) {
  const std::vector<double> t = {0.0, 10.0, 25.0, 30.0, 50.0};
  std::vector<double> T;
  for (double x : t) T.push_back(Ramp(x));
  const std::vector<double> r = RatePerMinute(t, T);
  ASSERT_EQ(r.size(), t.size());
  for (double v : r) EXPECT_NEAR(v, kRampRate_C_per_min, kRateRoundOff_C_per_min);
}

TEST(RatePerMinute, IsNaNWithFewerThanTwoValues) {
  const std::vector<double> r = RatePerMinute({0.0}, {20.0});
  ASSERT_EQ(r.size(), 1u);
  EXPECT_TRUE(std::isnan(r[0]));
}

TEST(GroupMeans, AveragesFullGroupsAndLeavesTheRemainderOut) {
  EXPECT_EQ(GroupMeans({1.0, 3.0, 5.0, 7.0, 100.0}, 2), (std::vector<double>{2.0, 6.0}));  // exact in binary
  EXPECT_EQ(GroupMeans({1.0, 2.0}, 1), (std::vector<double>{1.0, 2.0}));
}

TEST(ResidualTable, HasPerChannelTheDataItsRateAndBothResidualsInReportOrder) {
  const ResidualTable table = MakeResidualTable(TraceDiagnosis());
  using Kind = ResidualColumn::Kind;
  const std::vector<std::pair<std::string, Kind>> expected = {
      {"measured_T1", Kind::kMeasured},       {"dTdt_T1_C_per_min", Kind::kRate}, {"baseline_T1", Kind::kBaseline},
      {"extended_T1", Kind::kExtended},       {"measured_bias_dph", Kind::kMeasured},
      {"baseline_bias_dph", Kind::kBaseline}, {"extended_bias_dph", Kind::kExtended}};
  ASSERT_EQ(table.columns.size(), expected.size());
  for (size_t c = 0; c < expected.size(); ++c) {
    EXPECT_EQ(table.columns[c].name, expected[c].first);
    EXPECT_EQ(table.columns[c].kind, expected[c].second) << expected[c].first;
  }
  ASSERT_EQ(table.runs.size(), 2u);
  const ResidualTableRun& a = table.runs[0];
  EXPECT_EQ(a.run, "a");
  ASSERT_EQ(a.t_s.size(), 25u);
  ASSERT_EQ(a.values.size(), expected.size());
  for (const auto& v : a.values) EXPECT_EQ(v.size(), 25u);
  for (size_t k = 0; k < a.t_s.size(); ++k) {
    EXPECT_EQ(a.values[0][k], Ramp(a.t_s[k]));  // copies
    EXPECT_NEAR(a.values[1][k], kRampRate_C_per_min, kRateRoundOff_C_per_min) << k;
    EXPECT_EQ(a.values[2][k], 0.1);
    EXPECT_EQ(a.values[3][k], 0.01 * static_cast<double>(k));
    EXPECT_EQ(a.values[5][k], 0.02);
  }
}

TEST(ResidualTable, ARunWithoutAChannelHasItsCellsAbsent) {
  const ResidualTable table = MakeResidualTable(TraceDiagnosis());
  const ResidualTableRun& b = table.runs[1];
  EXPECT_EQ(b.run, "b");
  ASSERT_EQ(b.t_s.size(), 12u);
  for (size_t c = 0; c < 4; ++c) EXPECT_EQ(b.values[c].size(), 12u) << table.columns[c].name;
  for (size_t c = 4; c < 7; ++c) EXPECT_TRUE(b.values[c].empty()) << table.columns[c].name;
}

TEST(ResidualTable, NoResidualsGiveNoColumns) {
  const ResidualTable table = MakeResidualTable(BiasDiagnosis());
  EXPECT_TRUE(table.columns.empty());
  EXPECT_TRUE(table.runs.empty());
}

TEST(DiagnosisFigures, ShowScoreBlockMeansOfResidualsTemperatureAndRate) {
  const DiagnosisFigures f = MakeDiagnosisFigures(TraceDiagnosis(), "T1");
  EXPECT_EQ(f.score_block_s, 100.0);
  EXPECT_TRUE(f.extended);
  ASSERT_EQ(f.channels.size(), 2u);
  const ChannelFigure& t1 = f.channels[0];
  EXPECT_EQ(t1.channel, "T1");
  EXPECT_EQ(t1.temperature, "T1");
  ASSERT_EQ(t1.runs.size(), 2u);
  const ChannelFigureRun& a = t1.runs[0];
  EXPECT_EQ(a.blocks_per_score_block, 10u);  // 100 s score blocks of 10 s fit blocks
  ASSERT_EQ(a.t_s.size(), 25u);
  for (size_t k = 0; k < a.t_s.size(); ++k) {
    EXPECT_EQ(a.simulated_baseline[k], Ramp(a.t_s[k]) - 0.1);  // the same subtraction
    EXPECT_EQ(a.simulated_extended[k], Ramp(a.t_s[k]) - 0.01 * static_cast<double>(k));
  }
  // 25 blocks: two full score blocks, the last 5 blocks left out.
  ASSERT_EQ(a.residual_baseline.size(), 2u);
  ASSERT_EQ(a.rate_C_per_min.size(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    // Means of ten values: round-off of a sum of ten O(1) terms, below 1e-14 relative.
    EXPECT_NEAR(a.residual_baseline[i], 0.1, 1e-15);
    EXPECT_NEAR(a.residual_extended[i], 0.01 * (4.5 + 10.0 * static_cast<double>(i)), 1e-15);
    EXPECT_NEAR(a.temperature_C[i], Ramp(50.0 + 100.0 * static_cast<double>(i)), 1e-13);  // mid-time of the group
    EXPECT_NEAR(a.rate_C_per_min[i], kRampRate_C_per_min, kRateRoundOff_C_per_min);
  }
}

TEST(DiagnosisFigures, ShowTheBiasAgainstTheTemperatureGivenAndSkipRunsWithoutIt) {
  const DiagnosisFigures f = MakeDiagnosisFigures(TraceDiagnosis(), "T1");
  const ChannelFigure& bias = f.channels[1];
  EXPECT_EQ(bias.channel, "bias_dph");
  EXPECT_EQ(bias.temperature, "T1");
  ASSERT_EQ(bias.runs.size(), 1u);  // run "b" has no bias
  EXPECT_EQ(bias.runs[0].run, "a");
  ASSERT_EQ(bias.runs[0].temperature_C.size(), 2u);
  EXPECT_NEAR(bias.runs[0].temperature_C[0], Ramp(50.0), 1e-13);  // as above: ten O(20) terms
  EXPECT_TRUE(MakeDiagnosisFigures(TraceDiagnosis(), "T_none").channels[1].runs.empty());
}

TEST(DiagnosisFigures, WithoutAnAcceptedStepShowOnlyTheBaseline) {
  Diagnosis d = TraceDiagnosis();
  d.steps.clear();
  EXPECT_FALSE(MakeDiagnosisFigures(d, "T1").extended);
}

TEST(BiasTemperatureChannel, IsTheSensorOnTheBiasNodeElseTheFirst) {
  sim::GyroConfig g;
  g.sensors.resize(2);
  g.sensors[0].channel = "T2";
  g.sensors[0].node = 1;
  g.sensors[1].channel = "T1";
  g.sensors[1].node = 0;
  g.bias.node = 0;
  EXPECT_EQ(BiasTemperatureChannel(g), "T1");
  g.bias.node = 3;
  EXPECT_EQ(BiasTemperatureChannel(g), "T2");
}

}  // namespace
}  // namespace rlg::diagnosis
