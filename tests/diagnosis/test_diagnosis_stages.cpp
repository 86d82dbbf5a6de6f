// Stages 2-6 of a diagnosis as pure functions (diagnosis/statistics/score.h, statistics/rank.h, statistics/steps.h,
// statistics/identifiability.h, network/calibration_summary.h, statistics/screen.h, statistics/bias_fit.h): closed forms and
// properties on synthetic inputs. Nothing here simulates or fits.

#include <gtest/gtest.h>

#include <boost/math/distributions/non_central_chi_squared.hpp>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "diagnosis/statistics/bias_fit.h"
#include "diagnosis/network/calibration_summary.h"
#include "diagnosis/network/thermal_residuals.h"
#include "diagnosis/statistics/identifiability.h"
#include "diagnosis/statistics/power.h"
#include "diagnosis/statistics/rank.h"
#include "diagnosis/statistics/score.h"
#include "diagnosis/statistics/screen.h"
#include "diagnosis/statistics/steps.h"

namespace rlg::diagnosis {
namespace {

std::vector<double> WhiteNoise(size_t n, double sd, uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, sd);
  std::vector<double> x(n);
  for (double& v : x) v = normal(rng);
  return x;
}

// ---- scoring ----------------------------------------------------------------------------------

TEST(Summarise, SumsSquaresAndCountsAcrossSeriesWithoutCrossProductsAtTheirBoundaries) {
  // Two series [1, 1] and [-1, -1]: ssr 4, n 4; lag-1 products within series 1 + 1 = 2, the
  // boundary product 1 * -1 is not counted, so rho = 2 / 4.
  const ResidualFit f = Summarise({{1.0, 1.0}, {-1.0, -1.0}});
  EXPECT_EQ(f.n, 4);
  EXPECT_DOUBLE_EQ(f.ssr, 4.0);
  EXPECT_DOUBLE_EQ(f.rho, 0.5);
  EXPECT_DOUBLE_EQ(f.rms(), 1.0);
}

TEST(Summarise, ClampsTheAutocorrelationToZeroAndNineTenths) {
  EXPECT_EQ(Summarise({{1.0, -1.0, 1.0, -1.0}}).rho, 0.0);  // alternating: -3/4 clamped up
  EXPECT_EQ(Summarise({std::vector<double>(100, 1.0)}).rho, 0.9);  // constant: 99/100 clamped down
  EXPECT_EQ(Summarise({}).rho, 0.0);
  EXPECT_EQ(Summarise({}).rms(), 0.0);
}

TEST(InformationGain, IsTheBicOnWhiteResidualsAndShrinksWithTheirAutocorrelation) {
  // White baseline (rho 0), n = 100, ssr 100 (s² = 1); an extension with one parameter that
  // halves the ssr gains 50 - ln 100.
  const ResidualFit base{100.0, 100, 0.0}, ext{50.0, 100, 0.0};
  EXPECT_NEAR(InformationGain(base, ext, 1), 50.0 - std::log(100.0), 1e-12);  // round-off only
  // rho = 0.5: n_eff = 100 / 3, so the reduction counts a third and the penalty ln(100 / 3).
  const ResidualFit wandering{100.0, 100, 0.5};
  EXPECT_NEAR(InformationGain(wandering, ext, 1), 50.0 / 3.0 - std::log(100.0 / 3.0), 1e-12);
  // No reduction: the penalty alone, k ln n_eff.
  EXPECT_NEAR(InformationGain(base, base, 2), -2.0 * std::log(100.0), 1e-12);
  // n_eff below 2 is penalised as 2.
  const ResidualFit tiny{1.0, 2, 0.9};
  EXPECT_NEAR(InformationGain(tiny, tiny, 1), -std::log(2.0), 1e-12);
}

TEST(HeldOutRmsRatio, IsTheRatioOfRmsAndOneWithNothingToCompare) {
  EXPECT_DOUBLE_EQ(HeldOutRmsRatio(4.0, 1.0), 2.0);
  EXPECT_DOUBLE_EQ(HeldOutRmsRatio(1.0, 4.0), 0.5);
  EXPECT_DOUBLE_EQ(HeldOutRmsRatio(1.0, 0.0), 1.0);
}

TEST(LjungBoxP, IsUniformOnWhiteNoiseAndTinyOnAnAutoregression) {
  // Over 400 white series the p-value falls below 0.05 in about 5 %: 20 expected, binomial sd
  // 4.4; 8..34 is 2.7 sd either side (the chi² approximation for n = 200 is good to ~1 %).
  int below = 0;
  for (uint32_t seed = 0; seed < 400; ++seed) below += LjungBoxP(WhiteNoise(200, 1.0, seed), 10) < 0.05;
  EXPECT_GE(below, 8);
  EXPECT_LE(below, 34);
  // AR(1) with phi 0.8: rho_1 = 0.8 alone gives Q ~ 200 * 0.64 = 128 on 10 lags, p ~ 1e-22.
  std::vector<double> ar = WhiteNoise(200, 1.0, 7);
  for (size_t i = 1; i < ar.size(); ++i) ar[i] += 0.8 * ar[i - 1];
  EXPECT_LT(LjungBoxP(ar, 10), 1e-10);
  EXPECT_EQ(LjungBoxP({1.0, 2.0, 3.0}, 10), 1.0);          // too short
  EXPECT_EQ(LjungBoxP(std::vector<double>(50, 3.0), 10), 1.0);  // constant
}

TEST(NullThreshold, IsTheLargestReplicateButNeverBelowTheCriterion) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(NullThreshold({3.0, 25.0, -inf, 12.0}, 10.0), 25.0);
  EXPECT_EQ(NullThreshold({3.0, -inf}, 10.0), 10.0);
  EXPECT_EQ(NullThreshold({}, 10.0), 10.0);
}

// ---- ranking ----------------------------------------------------------------------------------

/// A candidate of a held-out gain `gain` (information units; acceptance asks it to exceed 0).
Candidate Make(const std::string& cause, const std::string& target, CandidateKind kind, double score, double gain,
               std::map<std::string, double> parameters = {}) {
  Candidate c;
  c.cause = cause;
  c.target = target;
  c.kind = kind;
  c.score = score;
  c.heldout_gain = gain;
  c.parameters = std::move(parameters);
  return c;
}

RankingRule Rule() {
  RankingRule r;
  r.thermal_threshold = 10.0;
  r.bias_threshold = 30.0;
  r.min_heldout_gain = 0.0;
  return r;
}

TEST(Significant, NeedsTheScoreOfItsKindAndAHeldOutGain) {
  const RankingRule r = Rule();
  EXPECT_TRUE(Significant(Make("thermal.missing_link", "a-b", CandidateKind::kThermal, 10.0, 0.5), r));
  EXPECT_FALSE(Significant(Make("thermal.missing_link", "a-b", CandidateKind::kThermal, 9.9, 40.0), r));
  EXPECT_FALSE(Significant(Make("thermal.missing_link", "a-b", CandidateKind::kThermal, 99.0, 0.0), r));  // must exceed 0
  EXPECT_FALSE(Significant(Make("bias.gradient", "a-b", CandidateKind::kBias, 29.0, 40.0), r));  // below the bootstrap's threshold
  EXPECT_TRUE(Significant(Make("bias.gradient", "a-b", CandidateKind::kBias, 30.0, 0.1), r));
  EXPECT_FALSE(Significant(Make("bias.gradient", "a-b", CandidateKind::kBias, 300.0, -3.0), r));
  EXPECT_FALSE(Significant(Make("thermal.radiation", "a-b", CandidateKind::kThermalScreened, 500.0, 40.0), r));
  EXPECT_FALSE(Significant(Make("thermal.radiation", "a-b", CandidateKind::kThermalNoEffect, 500.0, 40.0), r));
  // Without a thermal network the held-out RMS ratio is asked as well (the polynomial family's
  // residuals are not prewhitened).
  DiagnoseOptions o;
  const RankingRule without = RankingRule::WithoutNetwork(o, 30.0);
  Candidate c = Make("bias.gradient", "a-b", CandidateKind::kBias, 30.0, 0.1);
  c.heldout_rms_ratio = 1.04;
  EXPECT_TRUE(Significant(c, r));
  EXPECT_FALSE(Significant(c, without));
  c.heldout_rms_ratio = 1.05;
  EXPECT_TRUE(Significant(c, without));
  EXPECT_FALSE(without.plausible_first);
  EXPECT_EQ(RankingRule::WithNetwork(o, 12.0, 30.0).min_heldout_ratio, 0.0);
}

TEST(Rank, PutsSignificantThermalFirstThenSignificantBiasThenTheRestEachByScore) {
  const std::vector<Candidate> c = {
      Make("thermal.radiation", "block-case", CandidateKind::kThermal, 500.0, 0.0),     // 0: fails held-out
      Make("thermal.missing_link", "a-b", CandidateKind::kThermal, 20.0, 1.2),          // 1: significant thermal
      Make("bias.gradient", "a-b", CandidateKind::kBias, 400.0, 2.0),                   // 2: significant bias
      Make("bias.temperature_rate", "T1", CandidateKind::kBias, 600.0, 3.0),            // 3: significant bias, best score
      Make("sensor.lag", "T2", CandidateKind::kThermalScreened, 900.0, 0.0),         // 4: not refitted
      Make("thermal.missing_mass", "a-b", CandidateKind::kThermal, 15.0, 1.1),          // 5: significant thermal
  };
  EXPECT_EQ(Rank(c, Rule()), (std::vector<size_t>{1, 5, 3, 2, 4, 0}));
}

TEST(Rank, TakesTheTwinWithTheBetterHeldOutGainThenTheMorePlausible) {
  // Equal scores to tie_score: exact twins. The second has the better held-out gain.
  std::vector<Candidate> c = {Make("bias.gradient", "block-cabinet", CandidateKind::kBias, 100.0, 2.0, {{"k_dph_per_C", 0.01}}),
                              Make("bias.temperature_rate", "T1", CandidateKind::kBias, 100.0, 2.5, {{"k_dph_per_C_per_min", 0.04}})};
  EXPECT_EQ(Rank(c, Rule()).front(), 1u);
  // Equal held-out gains too: the smaller parameter on the catalog's scale leads (Effect::
  // Implausibility; a gradient of 100 °/h/°C is far outside its range, 0.01 well inside).
  c[1].heldout_gain = 2.0;
  c[0].parameters["k_dph_per_C"] = 100.0;
  EXPECT_EQ(Rank(c, Rule()).front(), 1u);
  // A near tie (1 point apart) is not a twin: the score decides (both inside their ranges).
  c[0].parameters["k_dph_per_C"] = 0.01;
  c[1].score = 99.0;
  c[1].heldout_gain = 9.0;
  EXPECT_EQ(Rank(c, Rule()).front(), 0u);
}

TEST(Rank, PutsACauseInsideItsRangeBeforeAStandInOutsideItThatScoresHigher) {
  // TCLab's first search: a heater power falling 2.6 %/°C (the catalog's range is ±1 %/°C) out-
  // scores the link between the heaters; the link, inside its range, is ranked first.
  const std::vector<Candidate> c = {
      Make("thermal.power_drift", "heater2", CandidateKind::kThermal, 137.4, 1.32, {{"g_per_C", -0.026}}),  // 0: stand-in
      Make("thermal.missing_link", "heater1-heater2", CandidateKind::kThermal, 125.5, 1.27, {{"conductance_W_per_K", 0.0014}}),  // 1
      Make("thermal.power_drift", "heater1", CandidateKind::kThermal, 30.0, 1.1, {{"g_per_C", -0.005}}),  // 2: inside
      Make("thermal.radiation", "heater1-heater2", CandidateKind::kThermal, 64.6, 0.0),  // 3: not significant
  };
  EXPECT_EQ(Rank(c, Rule()), (std::vector<size_t>{1, 2, 0, 3}));
  // A stand-in that out-scores the leader by more than a twin's tie_score is no twin of it,
  // whatever its held-out gain (a twin rule comparing signed score differences would take
  // TCLab's drift, 26 points above the link, for the link's twin).
  std::vector<Candidate> d = {c[0], c[1]};
  d[0].heldout_gain = 9.0;
  EXPECT_EQ(Rank(d, Rule()).front(), 1u);
  // A stand-in still leads when nothing inside its range is significant.
  EXPECT_EQ(Rank({c[0], c[3]}, Rule()).front(), 0u);
}

TEST(Rank, TakesCausesOutsideTheCatalogAsPlausibleAndRanksByScoreAloneWhenAsked) {
  // Without a thermal network the model family's terms compete with the catalog's (poly.lag has
  // no effect object); a rate of 3 °/h per °C/min is outside the catalog's ±1.
  const std::vector<Candidate> c = {
      Make("bias.temperature_rate", "T1", CandidateKind::kBias, 120.0, 2.0, {{"k_dph_per_C_per_min", 3.0}}),  // 0: stand-in
      Make("poly.lag", "T1", CandidateKind::kBias, 100.0, 2.5, {{"k_dph_per_C", 0.7}, {"tau_s", 300.0}}),      // 1
  };
  EXPECT_EQ(Rank(c, Rule()).front(), 1u);  // plausible first: the term outside the catalog counts as plausible
  RankingRule by_score = Rule();
  by_score.plausible_first = false;
  EXPECT_EQ(Rank(c, by_score).front(), 0u);
  // Led by it, the stand-in that out-scored it is still listed as set aside; and ties among terms
  // outside the catalog, which have no advice of their own, get the bias kind's general advice.
  const auto ties = Ties({c[1], c[0]}, Rule());
  ASSERT_EQ(ties.size(), 1u);
  EXPECT_FALSE(ties.front().plausible);
  const auto notes = TieNotes(c[1], {{"poly.hysteresis", "T1", -2.0, true, 0.0, true}}, false, Rule().tie_score);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes.front().find("separates rate from gradient terms"), std::string::npos) << notes.front();
}

TEST(Ties, AreSignificantCandidatesOfTheLeadersKindWithinTheBandOnTheFitOrTheHeldOutData) {
  const std::vector<Candidate> ranked = {
      Make("bias.temperature_rate", "T1", CandidateKind::kBias, 100.0, 40.0, {{"k_dph_per_C_per_min", 0.1}}),
      Make("bias.gradient", "block-cabinet", CandidateKind::kBias, 95.0, 20.0, {{"k_dph_per_C", 0.01}}),  // tie, -5
      Make("bias.hysteresis", "block", CandidateKind::kBias, 89.0, 29.0,
           {{"k_heating_minus_cooling_dph_per_C", 0.001}}),         // 11 points below, 11 held out: not a tie
      Make("bias.mode_hop", "T1", CandidateKind::kBias, 70.0, 31.0),  // 30 points below, 9 held out: a tie
      Make("thermal.missing_link", "a-b", CandidateKind::kThermal, 99.0, 40.0),  // other kind
      Make("bias.gradient", "anode-block", CandidateKind::kBias, 98.0, 0.0),     // within the band, fails held-out
  };
  const std::vector<Tie> ties = Ties(ranked, Rule());
  ASSERT_EQ(ties.size(), 2u);
  EXPECT_EQ(ties[0].cause, "bias.gradient");
  EXPECT_EQ(ties[0].target, "block-cabinet");
  EXPECT_DOUBLE_EQ(ties[0].score_difference, -5.0);
  EXPECT_DOUBLE_EQ(ties[0].heldout_difference, -20.0);
  EXPECT_TRUE(ties[0].ambiguous);
  EXPECT_EQ(ties[1].cause, "bias.mode_hop");
  EXPECT_DOUBLE_EQ(ties[1].score_difference, -30.0);
  EXPECT_DOUBLE_EQ(ties[1].heldout_difference, -9.0);
  EXPECT_TRUE(ties[1].ambiguous);
  // No significant leader: no ties.
  std::vector<Candidate> weak = ranked;
  weak[0].heldout_gain = 0.0;
  EXPECT_TRUE(Ties(weak, Rule()).empty());
}

TEST(Ties, ListAStandInTheDataPreferredBeyondTheBandAndMarkEachTiesPlausibility) {
  // refgen's rate term of 1.23 °/h per °C/min (the catalog's range ends at 1) out-scored the
  // gradient taken for it by 17 points: ranked after it for its size, listed as set aside.
  std::vector<Candidate> c = {
      Make("bias.temperature_rate", "T1", CandidateKind::kBias, 444.4, 540.0, {{"k_dph_per_C_per_min", 1.23}}),  // stand-in
      Make("bias.gradient", "anode-cabinet", CandidateKind::kBias, 427.7, 350.0, {{"k_dph_per_C", -0.018}}),
      Make("bias.gradient", "block-cabinet", CandidateKind::kBias, 427.6, 350.0, {{"k_dph_per_C", -0.018}}),
  };
  std::vector<Candidate> ranked;
  for (size_t i : Rank(c, Rule())) ranked.push_back(c[i]);
  ASSERT_EQ(ranked.front().target, "anode-cabinet");
  const std::vector<Tie> ties = Ties(ranked, Rule());
  ASSERT_EQ(ties.size(), 2u);
  EXPECT_EQ(ties[0].target, "block-cabinet");
  EXPECT_TRUE(ties[0].plausible);
  EXPECT_TRUE(ties[0].ambiguous);
  EXPECT_EQ(ties[1].cause, "bias.temperature_rate");
  EXPECT_FALSE(ties[1].plausible);
  EXPECT_FALSE(ties[1].ambiguous);  // set aside for its size, not left open by the data
  EXPECT_NEAR(ties[1].score_difference, 16.7, 1e-9);  // 444.4 - 427.7
  // A plausible candidate more than the band below on both the fit and the held-out data is
  // not a tie (one above would lead); at the same held-out gain it is.
  const std::vector<Candidate> far = {
      Make("bias.gradient", "anode-cabinet", CandidateKind::kBias, 427.7, 350.0, {{"k_dph_per_C", -0.018}}),
      Make("bias.hysteresis", "block", CandidateKind::kBias, 400.0, 300.0, {{"k_heating_minus_cooling_dph_per_C", 0.001}})};
  EXPECT_TRUE(Ties(far, Rule()).empty());
  std::vector<Candidate> held_alike = far;
  held_alike[1].heldout_gain = 350.0;
  ASSERT_EQ(Ties(held_alike, Rule()).size(), 1u);
  EXPECT_TRUE(Ties(held_alike, Rule())[0].ambiguous);
}

TEST(Ties, ComparePairsByTheScoreDifferencesGivenAndByTheirScoresWhereNaN) {
  // 27.7 points behind on their own scores and far behind on held-out data: apart...
  const std::vector<Candidate> ranked = {
      Make("bias.gradient", "cathode-cabinet", CandidateKind::kBias, 427.7, 350.0, {{"k_dph_per_C", 0.005}}),
      Make("bias.gradient", "cathode-block", CandidateKind::kBias, 400.0, 300.0, {{"k_dph_per_C", 0.03}}),
      Make("bias.temperature_rate", "T4", CandidateKind::kBias, 400.0, 300.0, {{"k_dph_per_C_per_min", 0.1}})};
  EXPECT_TRUE(Ties(ranked, Rule()).empty());
  // ... but 9.5 behind under one noise model: a tie, reported at that difference; a NaN
  // difference is the scores' (the rate stays apart).
  const double nan = std::nan("");
  const std::vector<Tie> ties = Ties(ranked, Rule(), {nan, -9.5, nan});
  ASSERT_EQ(ties.size(), 1u);
  EXPECT_EQ(ties[0].target, "cathode-block");
  EXPECT_TRUE(ties[0].ambiguous);
  EXPECT_EQ(ties[0].score_difference, -9.5);
  EXPECT_EQ(ties[0].heldout_difference, -50.0);
  // The band is open: 10 behind under one model is apart, as 10 behind on the scores is.
  EXPECT_TRUE(Ties(ranked, Rule(), {nan, -10.0, -10.0}).empty());
}

TEST(TieNotes, ListTheTiesWithTheAdviceOfTheirKindAndTheStandInsSetAside) {
  const Candidate lead = Make("bias.temperature_rate", "T1", CandidateKind::kBias, 100.0, 2.0);
  EXPECT_TRUE(TieNotes(lead, {}, true, Rule().tie_score).empty());
  const auto notes = TieNotes(lead, {{"bias.hysteresis", "block", -4.25, true, -12.0, true}}, true, Rule().tie_score);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0].rfind("ambiguous: within 10 score points of bias.temperature_rate T1 on the fit or the held-out "
                           "data: bias.hysteresis block (-4.2, held out -12.0); ",
                           0),
            0u)
      << notes[0];
  EXPECT_NE(notes[0].find("separates rate from gradient terms"), std::string::npos) << notes[0];
  const Candidate thermal = Make("sensor.lag", "T2", CandidateKind::kThermal, 100.0, 2.0);
  const auto t = TieNotes(thermal, {{"thermal.missing_mass", "block-case", -1.0, true, 0.0, true}}, true, Rule().tie_score);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_NE(t[0].find("separate sensor lag from a missing mass"), std::string::npos) << t[0];
  // A stand-in within the band is a tie marked as such; one beyond it gets its own note.
  const Candidate grad = Make("bias.gradient", "anode-cabinet", CandidateKind::kBias, 427.7, 3.5);
  const auto s = TieNotes(grad, {{"bias.gradient", "block-cabinet", -0.1, true, -0.2, true},
                                 {"bias.temperature_rate", "T1", 16.7, false, 19.0, false},
                                 {"bias.hysteresis", "T1", 3.0, false, 2.5, true}},
                          true, Rule().tie_score);
  ASSERT_EQ(s.size(), 2u);
  EXPECT_NE(s[0].find("bias.gradient block-cabinet (-0.1, held out -0.2), bias.hysteresis T1 (+3.0, held out +2.5, "
                      "stand-in)"),
            std::string::npos)
      << s[0];
  EXPECT_EQ(s[1].rfind("set aside: the data prefer bias.temperature_rate T1 (+16.7, held out +19.0, stand-in) to "
                       "bias.gradient anode-cabinet, but only at a size outside the catalog's plausible range",
                       0),
            0u)
      << s[1];
}

TEST(TieNotes, NameExactTwinsAsSuchAndGiveAdviceOnlyForTheOtherTies) {
  // The held-out generator's cathode rate: the cathode has one link, so its rate is the
  // cathode-block gradient (score 3e-11 apart), and the anode-cathode gradient is that gradient
  // given the baseline's anode-block term (8e-9 apart). No run separates them: no advice.
  const Candidate lead = Make("bias.gradient", "cathode-block", CandidateKind::kBias, 3687.8, 2.0);
  const auto twins = TieNotes(lead,
                              {{"bias.temperature_rate", "T4", 3e-11, true, 1e-10, true},
                               {"bias.gradient", "anode-cathode", -8e-9, true, -6e-4, true}},
                              true, Rule().tie_score);
  ASSERT_EQ(twins.size(), 1u);
  EXPECT_NE(twins[0].find("; exact twins of it on these data (one prediction under several names; docs/diagnosis.md "
                          "says which stay twins on any run): bias.temperature_rate T4, bias.gradient anode-cathode"),
            std::string::npos)
      << twins[0];
  EXPECT_EQ(twins[0].find("separate"), std::string::npos) << twins[0];
  // Beside a near tie, the twins are named and the near tie gets its kind's advice: a
  // hysteresis 2 points behind is no twin (tie_score 1e-6).
  const auto mixed = TieNotes(lead,
                              {{"bias.temperature_rate", "T4", 3e-11, true, 1e-10, true},
                               {"bias.hysteresis", "block", -2.0, true, -5.0, true}},
                              true, Rule().tie_score);
  ASSERT_EQ(mixed.size(), 1u);
  EXPECT_NE(mixed[0].find("): bias.temperature_rate T4; a step or a dwell in ambient"), std::string::npos) << mixed[0];
}

// ---- steps ------------------------------------------------------------------------------------

TEST(LargestStep, FindsAStepOfKnownSizeAndTimeInWhiteNoise) {
  // 2000 blocks of sd 1 with a step of +1 at block 1200 (a 5.5 h run of 10 s blocks): the step
  // widens sigma to sqrt(1 + 0.24) and rho to ~0.19, so z ~ sqrt(480) / 1.11 / 1.21 ~ 16, above
  // the threshold; the split is found to within 30 blocks and the size to within 3 sd of a
  // two-sample difference (sqrt(1/1200 + 1/800) = 0.046).
  const size_t n = 2000;
  std::vector<double> e = WhiteNoise(n, 1.0, 3), t(n);
  for (size_t i = 0; i < n; ++i) {
    t[i] = 10.0 * static_cast<double>(i) + 5.0;
    if (i >= 1200) e[i] += 1.0;
  }
  const auto s = LargestStep(Eigen::Map<const Eigen::VectorXd>(e.data(), static_cast<Eigen::Index>(n)), t, "run-a");
  ASSERT_TRUE(s.has_value());
  EXPECT_EQ(s->run, "run-a");
  EXPECT_NEAR(s->t_s, 12005.0, 300.0);
  EXPECT_NEAR(s->size, 1.0, 0.14);
  EXPECT_GT(s->statistic, s->threshold);
  EXPECT_EQ(s->threshold, kStepThreshold);
  EXPECT_NE(StepNote(*s).find("run 'run-a': largest step of the bias residual +"), std::string::npos);
}

TEST(LargestStep, StaysBelowTheThresholdOnWhiteNoiseAndOnARandomWalkTheAr1FactorWidens) {
  // The maximum of the standardised two-sample statistic over splits of white noise is that of
  // a Brownian bridge, ~3-4 for n = 200: 9 is never reached in 50 series.
  for (uint32_t seed = 0; seed < 50; ++seed) {
    const std::vector<double> e = WhiteNoise(200, 1.0, seed);
    std::vector<double> t(200, 0.0);
    const auto s = LargestStep(Eigen::Map<const Eigen::VectorXd>(e.data(), 200), t, "r");
    ASSERT_TRUE(s.has_value());
    EXPECT_LT(s->statistic, kStepThreshold) << "seed " << seed;
  }
  // A strongly autocorrelated series (AR(1), phi 0.9) wanders; the factor sqrt((1+rho)/(1-rho))
  // keeps its statistic below the threshold in most series (without it, z ~ 3-4 x larger).
  int above = 0;
  for (uint32_t seed = 0; seed < 50; ++seed) {
    std::vector<double> e = WhiteNoise(200, 1.0, 100 + seed);
    for (size_t i = 1; i < e.size(); ++i) e[i] += 0.9 * e[i - 1];
    std::vector<double> t(200, 0.0);
    above += LargestStep(Eigen::Map<const Eigen::VectorXd>(e.data(), 200), t, "r")->statistic > kStepThreshold;
  }
  EXPECT_LE(above, 2);  // ~5 % at most of wandering nulls (the diagnosis suite's reached 8.2)
}

TEST(LargestStep, NeedsEnoughBlocksAndAVaryingSeries) {
  const std::vector<double> shortseries(19, 1.0), t19(19, 0.0);
  EXPECT_FALSE(LargestStep(Eigen::Map<const Eigen::VectorXd>(shortseries.data(), 19), t19, "r").has_value());
  const std::vector<double> flat(30, 2.0), t30(30, 0.0);
  EXPECT_FALSE(LargestStep(Eigen::Map<const Eigen::VectorXd>(flat.data(), 30), t30, "r").has_value());
}

// ---- identifiability --------------------------------------------------------------------------

/// A heat capacity, a link to ambient and a source's gain, as the calibration labels them.
const std::vector<KnobLabel> kThreeKnobs = {{"C:block", KnobKind::kHeatCapacity},
                                            {"G:block-ambient", KnobKind::kConductance, true},
                                            {"gain:discharge", KnobKind::kGain}};

TEST(AnalyseIdentifiability, CountsDeterminedDirectionsAndNamesTheLooseOneWithItsLoadings) {
  // Three knobs, prior sd 0.1. Posterior covariance = prior² on the common-scale direction
  // u = (1, 1, 1)/sqrt 3 (the data say nothing about it) and (0.01)² across it: one undetermined
  // direction with sd ratio 1, loadings 1/sqrt 3 each, the common-scale reason; two determined.
  const double prior = 0.1;
  const Eigen::Vector3d u = Eigen::Vector3d::Ones() / std::sqrt(3.0);
  const Eigen::Matrix3d cov = prior * prior * u * u.transpose() + 1e-4 * (Eigen::Matrix3d::Identity() - u * u.transpose());
  const Identifiability id = AnalyseIdentifiability(cov, kThreeKnobs, prior);
  EXPECT_EQ(id.knobs, 3);
  EXPECT_EQ(id.determined, 2);
  ASSERT_EQ(id.undetermined.size(), 1u);
  EXPECT_NEAR(id.undetermined[0].sd_ratio, 1.0, 1e-9);  // eigen-solver round-off
  ASSERT_EQ(id.undetermined[0].loadings.size(), 3u);
  for (const auto& [name, loading] : id.undetermined[0].loadings) EXPECT_NEAR(loading, 1.0 / std::sqrt(3.0), 1e-9);
  EXPECT_NE(id.undetermined[0].reason.find("common scale"), std::string::npos);
  const auto notes = IdentifiabilityNotes(id);
  ASSERT_EQ(notes.size(), 2u);
  EXPECT_EQ(notes[0].rfind("the data determine 2 of 3 combinations", 0), 0u) << notes[0];
  EXPECT_NE(notes[1].find("posterior/prior sd 1.00"), std::string::npos) << notes[1];
  EXPECT_TRUE(IdentifiabilityNotes(Identifiability{}).empty());
}

TEST(AnalyseIdentifiability, NamesPowerAgainstCouplingAndSortsLoadingsByMagnitude) {
  // Loose direction (gain, G:block-ambient) = (0.8, 0.6) with a zero loading on C: the
  // power-coupling reason; loadings sorted |0.8| > |0.6| > 0.
  const double prior = 0.05;
  Eigen::Vector3d v(0.0, 0.6, 0.8);
  const Eigen::Matrix3d cov = prior * prior * v * v.transpose() + 1e-8 * Eigen::Matrix3d::Identity();
  const Identifiability id = AnalyseIdentifiability(cov, kThreeKnobs, prior);
  ASSERT_EQ(id.undetermined.size(), 1u);
  const auto& l = id.undetermined[0].loadings;
  EXPECT_EQ(l[0].first, "gain:discharge");
  EXPECT_NEAR(l[0].second, 0.8, 1e-6);
  EXPECT_EQ(l[1].first, "G:block-ambient");
  EXPECT_NEAR(l[1].second, 0.6, 1e-6);
  EXPECT_NEAR(l[2].second, 0.0, 1e-6);
  EXPECT_NE(id.undetermined[0].reason.find("heating power against coupling"), std::string::npos);
}

TEST(CorrelationsGivenScale, RemovesTheCommonScaleAndFlagsTheScaleItself) {
  // Independent knobs of equal variance plus a large common-scale part: raw correlations near
  // +1, given the scale -1/(k-1) = -0.5 for k = 3 (the deviations from a common mean).
  const Eigen::Vector3d u = Eigen::Vector3d::Ones();
  const Eigen::Matrix3d cov = 100.0 * u * u.transpose() + Eigen::Matrix3d::Identity();
  const Eigen::MatrixXd r = CorrelationsGivenScale(cov);
  EXPECT_NEAR(r(0, 1), -0.5, 1e-9);
  EXPECT_NEAR(r(1, 2), -0.5, 1e-9);
  EXPECT_NEAR(r(0, 0), 1.0, 1e-9);
  // One knob alone, and two knobs that are exactly the scale: nothing left given it.
  const Eigen::Matrix2d scale_only = Eigen::Matrix2d::Constant(1.0);
  const Eigen::MatrixXd nan = CorrelationsGivenScale(scale_only);
  EXPECT_TRUE(std::isnan(nan(0, 1)));
}

// ---- the linear bias fit ---------------------------------------------------------------------

/// Three runs of 50 blocks: y = 2 x1 - 0.5 x2 + offset_r (+ noise), x1, x2 varying per run.
BiasDesign ThreeRuns(double noise_sd, uint32_t seed) {
  BiasDesign d;
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  const double offsets[3] = {0.3, -1.0, 5.0};
  for (int r = 0; r < 3; ++r) {
    Eigen::MatrixXd X(50, 2);
    Eigen::VectorXd y(50);
    for (int i = 0; i < 50; ++i) {
      X(i, 0) = std::sin(0.1 * i + r);
      X(i, 1) = 0.02 * i * (r + 1);
      y[i] = 2.0 * X(i, 0) - 0.5 * X(i, 1) + offsets[r] + noise_sd * normal(rng);
    }
    d.X.push_back(X);
    d.y.push_back(y);
  }
  d.prior_mean = Eigen::VectorXd::Zero(2);
  d.prior_weight = Eigen::VectorXd::Zero(2);
  return d;
}

TEST(FitBias, RecoversTheCoefficientsWhateverEachRunsOffset) {
  const BiasDesign d = ThreeRuns(0.0, 1);
  const Eigen::VectorXd beta = FitBias(d, {0, 1, 2});
  EXPECT_NEAR(beta[0], 2.0, 1e-12);  // noise-free: round-off of a 150 x 2 QR
  EXPECT_NEAR(beta[1], -0.5, 1e-12);
  for (int r = 0; r < 3; ++r) EXPECT_LT(BiasResidual(d, beta, r).norm(), 1e-11);
}

TEST(FitBias, APriorRowPullsAnUndeterminedCoefficientToItsMean) {
  // A column of zeros is not determined by the data: free, QR gives 0; with a prior row
  // (weight 1, mean 0.7) it is the prior's mean, and the determined one is untouched.
  BiasDesign d = ThreeRuns(0.0, 1);
  for (auto& X : d.X) {
    X.conservativeResize(Eigen::NoChange, 3);
    X.col(2).setZero();
  }
  d.prior_mean = Eigen::Vector3d(0.0, 0.0, 0.7);
  d.prior_weight = Eigen::Vector3d(0.0, 0.0, 1.0);
  const Eigen::VectorXd beta = FitBias(d, {0, 1, 2});
  EXPECT_NEAR(beta[2], 0.7, 1e-12);
  EXPECT_NEAR(beta[0], 2.0, 1e-12);
}

TEST(HeldOutBias, IsLeaveOneRunOutOrTheHeldOutRunsPrediction) {
  const BiasDesign d = ThreeRuns(0.1, 2);
  // Leave-one-run-out: run 1's residual is that of beta fitted on runs 0 and 2.
  const auto loro = HeldOutBias(d, {0, 1, 2}, {});
  ASSERT_EQ(loro.size(), 3u);
  EXPECT_TRUE(loro[1].isApprox(BiasResidual(d, FitBias(d, {0, 2}), 1), 1e-12));
  // Held-out run 2: beta from runs 0 and 1; runs 0 and 1 get no held-out residual.
  const auto held = HeldOutBias(d, {0, 1}, {2});
  EXPECT_EQ(held[0].size(), 0);
  EXPECT_TRUE(held[2].isApprox(BiasResidual(d, FitBias(d, {0, 1}), 2), 1e-12));
  // One run alone: its in-sample residual, at the noise (0.1) within 30 % (48 degrees of freedom).
  const auto one = HeldOutBias(d, {0}, {});
  EXPECT_NEAR(std::sqrt(one[0].squaredNorm() / 50.0), 0.1, 0.03);
}

TEST(CrossValidatedInTime, PredictsEachSpanFromTheOtherFold) {
  // Noise-free with an offset per run: every span predicted exactly (round-off of a 2 x 2 fit).
  const BiasDesign exact = ThreeRuns(0.0, 1);
  const auto cv = CrossValidatedInTime(exact, {0, 2}, 4);
  ASSERT_EQ(cv.size(), 3u);
  EXPECT_EQ(cv[1].size(), 0);  // run 1 not listed
  ASSERT_EQ(cv[2].size(), 50);
  EXPECT_LT(cv[0].norm() + cv[2].norm(), 1e-10);
  // A column seen only in the odd spans: the even fold cannot fit it (QR gives it 0), so the odd
  // spans' prediction errors are its term, about each span's mean; the even spans stay exact.
  BiasDesign d = exact;
  for (int r = 0; r < 3; ++r) {
    d.X[r].conservativeResize(Eigen::NoChange, 3);
    d.X[r].col(2).setZero();
    for (int i = 12; i < 25; ++i) d.X[r](i, 2) = i, d.y[r][i] += 0.3 * i;  // span 1 of 4 (rows 12-24)
  }
  d.prior_mean = d.prior_weight = Eigen::VectorXd::Zero(3);
  const auto odd = CrossValidatedInTime(d, {0, 1, 2}, 4);
  Eigen::VectorXd term = 0.3 * Eigen::VectorXd::LinSpaced(13, 12.0, 24.0);
  term.array() -= term.mean();
  EXPECT_TRUE(odd[1].segment(12, 13).isApprox(term, 1e-9));
  EXPECT_LT(odd[1].head(12).norm(), 1e-9);
  // With white noise of 0.1 the errors are at the noise: within 20 % (150 values, 12 spans' means
  // and 2 coefficients taken out).
  const auto noisy = CrossValidatedInTime(ThreeRuns(0.1, 2), {0, 1, 2}, 4);
  double ssr = 0.0;
  for (const auto& v : noisy) ssr += v.squaredNorm();
  EXPECT_NEAR(std::sqrt(ssr / 150.0), 0.1, 0.02);
}

TEST(ArInnovations, AreTheSeriesLessItsAutoregressionWithTheFirstPValuesDropped) {
  ArModel ar;
  ar.phi = {0.5};
  ar.sigma = 1.0;
  const Eigen::VectorXd v = Eigen::Vector4d(1.0, 2.0, 3.0, 4.0);
  EXPECT_TRUE(ArInnovations(ar, v).isApprox(Eigen::Vector3d(1.5, 2.0, 2.5), 1e-15));
  ar.phi = {0.5, 0.25};  // v_k - 0.5 v_{k-1} - 0.25 v_{k-2}: 3 - 1 - 0.25, 4 - 1.5 - 0.5
  EXPECT_TRUE(ArInnovations(ar, v).isApprox(Eigen::Vector2d(1.75, 2.0), 1e-15));
  EXPECT_EQ(ArInnovations(ar, v.head(2)).size(), 0);
  ar.phi.clear();  // white: unchanged
  EXPECT_TRUE(ArInnovations(ar, v).isApprox(v, 0.0));
}

TEST(Prewhiten, KeepsEachRunsOffsetRemovableAndEachPriorsSd) {
  // Noise-free data with an offset per run: the prewhitened fit recovers the coefficients
  // exactly, since a constant stays a constant (1 - sum phi) c_r that FitBias's centring removes.
  BiasDesign d = ThreeRuns(0.0, 1);
  ArModel ar;
  ar.phi = {0.9, -0.2};
  ar.sigma = 0.5;
  const BiasDesign w = Prewhiten(d, ar, 2.0);
  ASSERT_EQ(w.X[1].rows(), 48);
  const Eigen::VectorXd beta = FitBias(w, {0, 1, 2});
  EXPECT_NEAR(beta[0], 2.0, 1e-12);  // round-off of a 144 x 2 QR
  EXPECT_NEAR(beta[1], -0.5, 1e-12);
  // The prior rows were set against rows of sd 2; the prewhitened rows have sd 0.5: the
  // weight (row sd / prior sd) is a quarter, so the prior's own sd is unchanged.
  d.prior_weight = Eigen::Vector2d(0.0, 8.0);
  EXPECT_TRUE(Prewhiten(d, ar, 2.0).prior_weight.isApprox(Eigen::Vector2d(0.0, 2.0), 1e-15));
  // No noise model (sigma 0): the design as it was.
  EXPECT_TRUE(Prewhiten(d, ArModel{}, 2.0).y[0].isApprox(d.y[0], 0.0));
}

/// The information gain before its penalty (k = 0: the chi² part) of an irrelevant slowly varying
/// column on bias residuals made of white noise and a drift of an hour's correlation time (10 s
/// blocks, three runs of 2 h), fitted either by ordinary least squares (lag-1 effective sample
/// size) or prewhitened by the AR model of the baseline's residuals, as the bias search does.
double NullGain(uint32_t seed, bool prewhiten) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> phase(0.0, 6.283);
  const double phi = std::exp(-10.0 / 3600.0);  // Gauss-Markov over 10 s blocks, tau 1 h
  BiasDesign base, ext;
  for (int r = 0; r < 3; ++r) {
    const int n = 720;
    Eigen::MatrixXd X(n, 1), Xe(n, 2);
    Eigen::VectorXd y(n);
    double drift = 3.0 * normal(rng);  // stationary sd 3 (in white-noise units)
    const double ph = phase(rng);
    for (int i = 0; i < n; ++i) {
      drift = phi * drift + 3.0 * std::sqrt(1.0 - phi * phi) * normal(rng);
      X(i, 0) = 0.01 * i * (r + 1);                 // the baseline's regressor, a ramp
      Xe(i, 0) = X(i, 0);
      Xe(i, 1) = std::sin(6.283 * i / 240.0 + ph);  // the candidate: 40 min period
      y[i] = 0.7 * X(i, 0) + drift + normal(rng);
    }
    base.X.push_back(X), ext.X.push_back(Xe), base.y.push_back(y), ext.y.push_back(y);
  }
  base.prior_mean = base.prior_weight = Eigen::VectorXd::Zero(1);
  ext.prior_mean = ext.prior_weight = Eigen::VectorXd::Zero(2);
  const std::vector<int> runs = {0, 1, 2};
  auto residuals = [&runs](const BiasDesign& d) {
    const Eigen::VectorXd beta = FitBias(d, runs);
    std::vector<std::vector<double>> s;
    for (int r : runs) {
      const Eigen::VectorXd e = BiasResidual(d, beta, r);
      s.emplace_back(e.data(), e.data() + e.size());
    }
    return s;
  };
  if (prewhiten) {
    const ArModel ar = FitAr(residuals(base), 10);
    base = Prewhiten(base, ar, 1.0);
    ext = Prewhiten(ext, ar, 1.0);
  }
  return InformationGain(Summarise(residuals(base)), Summarise(residuals(ext)), 0);
}

/// Over seeds 1-300, how often a null gain (prewhitened or not) passes chi²_1's 5 % point,
/// 3.84: prewhitened 6..30 times (15 expected, binomial sd 3.8; the tests say what else the
/// band allows), otherwise more than 60 (over 4x the nominal rate).
void ExpectNullGainsCalibratedOnlyPrewhitened(double (*gain)(uint32_t seed, bool prewhiten)) {
  int white = 0, ordinary = 0;
  for (uint32_t seed = 1; seed <= 300; ++seed) {
    white += gain(seed, true) > 3.84;
    ordinary += gain(seed, false) > 3.84;
  }
  EXPECT_GE(white, 6);
  EXPECT_LE(white, 30);
  EXPECT_GT(ordinary, 60);
}

TEST(Prewhiten, MakesTheScoreOfAnIrrelevantSlowTermAChiSquareOfOneDegree) {
  // Without a missing term, the gain before its penalty of one added column is a chi² of one
  // degree when the residuals are white: above 3.84 in 5 % of datasets. Over 300 seeds, 15 expected, binomial
  // sd 3.8; 6..30 allows the AR model's own fit error (an AR(10) stands in for white noise plus
  // an AR(1)). Ordinary least squares with the lag-1 effective sample size takes the drift for
  // evidence far more often: the 1 h drift is nearly a random walk at 10 s, whose lag-1
  // correlation says little about its power at the candidate's 40 min period (seeds 1-300: 10
  // prewhitened, 94 ordinary).
  ExpectNullGainsCalibratedOnlyPrewhitened(NullGain);
}

TEST(ThermalGlsGain, OnWhiteResidualsIsTheLogLikelihoodRatioOfEachChannel) {
  // Order 0 (no prewhitening): each channel adds n ln(SSR_base / SSR_ext) over the runs asked
  // for; run 1 is left out, and a channel no run has adds nothing.
  ThermalResidualSet base(2), ext(2);
  base[0] = {{1.0, -1.0, 2.0}, {0.5, 0.5}, {}};
  ext[0] = {{0.5, -0.5, 1.0}, {0.5, 0.5}, {}};
  base[1] = {{9.0, 9.0, 9.0}, {9.0, 9.0}, {}};
  ext[1] = {{0.0, 0.0, 0.0}, {0.0, 0.0}, {}};
  const double gain = ThermalGlsGain(base, ext, {0}, {0, 0, 0});
  EXPECT_NEAR(gain, 3.0 * std::log(4.0) + 0.0, 1e-12);  // T1 halves its residuals; T2 unchanged
  EXPECT_EQ(ThermalGlsGain(base, base, {0, 1}, {0, 0, 0}), 0.0);
}

TEST(ThermalGlsGain, CountsTheInnovationsOfEachRunAfterItsFirstValues) {
  // Order 2: an extension that halves the base exactly has the base's AR model at half its
  // scale, so every innovation halves and the gain is n ln 4, n the innovations: a run of 50
  // blocks has 48, a run of one block (shorter than the order) none.
  std::mt19937 rng(3);
  std::normal_distribution<double> normal(0.0, 1.0);
  ThermalResidualSet base(2, std::vector<std::vector<double>>(1));
  double x = 0.0;
  for (int i = 0; i < 50; ++i) base[0][0].push_back(x = 0.6 * x + normal(rng));
  base[1][0] = {0.3};
  ThermalResidualSet ext = base;
  for (auto& run : ext)
    for (double& v : run[0]) v *= 0.5;
  EXPECT_NEAR(ThermalGlsGain(base, ext, {0, 1}, {2}), 48.0 * std::log(4.0), 1e-9);
}

/// One channel's residual on 10 s fit blocks over three runs of 2 h: white noise plus a slow
/// misfit (Gauss-Markov, 20 min, sd 2 in white-noise units), and what a candidate that follows
/// an irrelevant 40 min term leaves when fitted to it by least squares, as a thermal refit is.
/// Returns the candidate's score before its penalty: prewhitened (ThermalGlsGain, the order the
/// base's residuals choose) or as a chi² in units of the base's variance.
double ThermalNullGain(uint32_t seed, bool prewhiten) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_real_distribution<double> phase(0.0, 6.283);
  const double phi = std::exp(-10.0 / 1200.0);
  ThermalResidualSet base(3, std::vector<std::vector<double>>(1));
  std::vector<std::vector<double>> x(3);
  double sxx = 0.0, sxy = 0.0;
  for (int r = 0; r < 3; ++r) {
    double drift = 2.0 * normal(rng);
    const double ph = phase(rng);
    for (int i = 0; i < 720; ++i) {
      drift = phi * drift + 2.0 * std::sqrt(1.0 - phi * phi) * normal(rng);
      base[r][0].push_back(drift + normal(rng));
      x[r].push_back(std::sin(6.283 * i / 240.0 + ph));
      sxx += x[r].back() * x[r].back();
      sxy += x[r].back() * base[r][0].back();
    }
  }
  ThermalResidualSet ext = base;
  double ssr_base = 0.0, ssr_ext = 0.0;
  for (int r = 0; r < 3; ++r)
    for (int i = 0; i < 720; ++i) {
      ext[r][0][i] -= sxy / sxx * x[r][i];
      ssr_base += base[r][0][i] * base[r][0][i];
      ssr_ext += ext[r][0][i] * ext[r][0][i];
    }
  const std::vector<int> runs = {0, 1, 2};
  if (prewhiten) return ThermalGlsGain(base, ext, runs, ThermalArOrders(base, runs, 1));
  return (ssr_base - ssr_ext) / (ssr_base / 2160.0);
}

TEST(ThermalGlsGain, MakesTheScoreOfAnIrrelevantSlowTermAChiSquareOfOneDegree) {
  // Without a missing effect the gain of one fitted parameter is a chi² of one degree when the
  // residuals' noise model is right: above 3.84 in 5 % of datasets, 15 of 300 (binomial sd
  // 3.8); 6..30 allows the AR model's fit error (fitted to the candidate's own residuals, it
  // favours the candidate a little: 19 seen) and its least-squares fit (not GLS), which lowers
  // the gain. The chi² in the base's variance, the score before, takes the slow misfit for
  // evidence: the 40 min term borrows the misfit's power at its period, which white-noise units
  // count many times over (seeds 1-300: 19 prewhitened, 213 in the base's variance).
  ExpectNullGainsCalibratedOnlyPrewhitened(ThermalNullGain);
}

TEST(Power, DetectionNoncentralityOfOneDegreeHasItsNormalForm) {
  // One degree: chi²_1(lambda) = (Z + sqrt(lambda))², so P(>= c²) = Phi(sqrt(lambda) - c) +
  // Phi(-sqrt(lambda) - c), computed here without Boost's noncentral chi²; the bisection stops
  // at a relative 1e-10 in sqrt(lambda), far inside 1e-8 in probability.
  auto phi = [](double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); };
  for (double critical : {3.84, 21.5, 45.0})
    for (double power : {0.5, 0.9, 0.99}) {
      const double m = std::sqrt(DetectionNoncentrality(critical, 1, power)), c = std::sqrt(critical);
      EXPECT_NEAR(phi(m - c) + phi(-m - c), power, 1e-8) << critical << " " << power;
    }
  EXPECT_EQ(DetectionNoncentrality(0.0, 1, 0.9), 0.0);  // every dataset reaches a critical value of 0
  // t = 10, 1e5 residuals: 90 % needs lambda = 35.04 (SciPy's ncx2.sf, docs/diagnosis.md).
  EXPECT_NEAR(DetectionNoncentrality(10.0 + std::log(1e5), 1, 0.9), 35.04, 0.01);
}

/// Fraction of `draws` datasets y = sqrt(lambda) p + z in R^3 (z standard normal, p unit) whose
/// projection on p reaches `critical` and out-scores every rival direction q (|q.y| < |p.y|).
double NamedFraction(double lambda, double critical, const std::vector<Eigen::Vector3d>& rivals, int draws) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal(0.0, 1.0);
  const Eigen::Vector3d p(1.0, 0.0, 0.0);
  int named = 0;
  for (int i = 0; i < draws; ++i) {
    const Eigen::Vector3d y = std::sqrt(lambda) * p + Eigen::Vector3d(normal(rng), normal(rng), normal(rng));
    bool ok = p.dot(y) * p.dot(y) >= critical;
    for (const auto& q : rivals) ok = ok && std::abs(q.dot(y)) < std::abs(p.dot(y));
    named += ok;
  }
  return static_cast<double>(named) / draws;
}

TEST(Power, NamingNoncentralityBoundsTheChanceOfBeatingEveryRival) {
  // Two rivals at cosines 0.9 and -0.5 (unit vectors in R^3), critical 21.5, one degree: at the
  // lambda returned, the Monte Carlo chance of being detected and ahead of both is at least
  // 0.9 (the union bound is a lower bound; 20,000 draws, binomial sd 0.002, so 0.895 allows
  // 2.5 sd), and at a third less lambda it is below 0.9 (the bound is not loose by that much).
  const double critical = 21.5;
  const std::vector<Eigen::Vector3d> rivals = {Eigen::Vector3d(0.9, std::sqrt(1.0 - 0.81), 0.0),
                                               Eigen::Vector3d(-0.5, 0.0, std::sqrt(0.75))};
  const double lambda = NamingNoncentrality(critical, 1, {0.9, -0.5}, 0.9);
  EXPECT_GT(lambda, DetectionNoncentrality(critical, 1, 0.9));  // the 0.9 rival binds
  EXPECT_GE(NamedFraction(lambda, critical, rivals, 20000), 0.895);
  EXPECT_LT(NamedFraction(lambda / 1.5, critical, rivals, 20000), 0.9);
  // No rival: detection alone. A twin: never.
  EXPECT_DOUBLE_EQ(NamingNoncentrality(critical, 1, {}, 0.9), DetectionNoncentrality(critical, 1, 0.9));
  EXPECT_TRUE(std::isinf(NamingNoncentrality(critical, 1, {0.3, -1.0}, 0.9)));
}

TEST(Power, ASecondDegreeNeedsMoreNoncentralityOnlyThroughItsPenalty) {
  // chi²_2(lambda) is chi²_1(lambda) plus a noise-only chi²_1: against one critical value it
  // reaches it with less lambda; the search asks ln n more of a second parameter (here
  // n = 1e5), and then it needs more. Boost's noncentral chi², its complement at the result.
  const double ln_n = std::log(1e5);
  const double one = DetectionNoncentrality(10.0 + ln_n, 1, 0.9), two = DetectionNoncentrality(10.0 + ln_n, 2, 0.9);
  EXPECT_LT(two, one);
  const double penalised = DetectionNoncentrality(10.0 + 2.0 * ln_n, 2, 0.9);
  EXPECT_GT(penalised, one);
  const boost::math::non_central_chi_squared chi2(2.0, penalised);
  EXPECT_NEAR(boost::math::cdf(boost::math::complement(chi2, 10.0 + 2.0 * ln_n)), 0.9, 1e-8);
}

TEST(LogLikelihoodRatio, IsThatOfGaussianResidualsWithTheirVarianceProfiled) {
  const ResidualFit base{200.0, 100, 0.0}, ext{100.0, 100, 0.0};
  EXPECT_NEAR(LogLikelihoodRatio(base, ext), 100.0 * std::log(2.0), 1e-12);
  EXPECT_NEAR(LogLikelihoodRatio(ext, base), -100.0 * std::log(2.0), 1e-12);
  EXPECT_EQ(LogLikelihoodRatio(ResidualFit{}, ext), 0.0);  // nothing held out
  EXPECT_NEAR(LogLikelihoodRatio(base, ResidualFit{0.0, 100, 0.0}), 100.0 * std::log(1e300), 1e-9);  // finite
}

// ---- thermal screening ------------------------------------------------------------------------

TEST(ScoreTest, CreditsOnlyWhatTheKnobsCannotExplainWithItsClosedForm) {
  // Knob Jacobian: the first two axes of R^5. A candidate column j = (1, 0, 3, 0, 0): its part
  // across the knobs is p = (0, 0, 3, 0, 0). Residual r0 = (5, 1, -6, 0, 0.5): p.r0 = -18, so
  // step = 18 / 9 = 2 and gain = 324 / 9 = 36.
  Eigen::MatrixXd J0 = Eigen::MatrixXd::Zero(5, 2);
  J0(0, 0) = 2.0;
  J0(1, 1) = -1.0;
  const Eigen::MatrixXd Q0 = KnobBasis(J0);
  EXPECT_TRUE((Q0.transpose() * Q0).isApprox(Eigen::Matrix2d::Identity(), 1e-14));
  Eigen::VectorXd j(5), r0(5);
  j << 1.0, 0.0, 3.0, 0.0, 0.0;
  r0 << 5.0, 1.0, -6.0, 0.0, 0.5;
  const auto s = ScoreTest(Q0, j, r0);
  ASSERT_TRUE(s.has_value());
  EXPECT_NEAR(s->step, 2.0, 1e-12);
  EXPECT_NEAR(s->gain, 36.0, 1e-12);
  // A candidate the knobs can imitate entirely is not screened in.
  Eigen::VectorXd inside(5);
  inside << 4.0, 2.0, 0.0, 0.0, 0.0;
  EXPECT_FALSE(ScoreTest(Q0, inside, r0).has_value());
}

TEST(ScoreTests, ScreensEveryColumnAsScoreTestScreensItAlone) {
  // A null bootstrap's replicates are screened as columns of one matrix: each column must get
  // exactly ScoreTest's gain and step (closed form above: p = (0, 0, 3, 0, 0)).
  Eigen::MatrixXd J0 = Eigen::MatrixXd::Zero(5, 2);
  J0(0, 0) = 2.0;
  J0(1, 1) = -1.0;
  const Eigen::MatrixXd Q0 = KnobBasis(J0);
  Eigen::VectorXd j(5);
  j << 1.0, 0.0, 3.0, 0.0, 0.0;
  Eigen::MatrixXd r(5, 3);
  r << 5.0, 0.0, 1.0,  //
      1.0, 2.0, 0.0,   //
      -6.0, 1.0, 0.0,  //
      0.0, 0.0, 2.0,   //
      0.5, 0.0, 0.0;
  const auto all = ScoreTests(Q0, j, r);
  ASSERT_TRUE(all.has_value());
  ASSERT_EQ(all->size(), 3u);
  const double gains[] = {36.0, 1.0, 0.0}, steps[] = {2.0, -1.0 / 3.0, 0.0};  // (p.r)² / 9, -(p.r) / 9
  for (Eigen::Index c = 0; c < 3; ++c) {
    const auto one = ScoreTest(Q0, j, r.col(c));
    ASSERT_TRUE(one.has_value());
    EXPECT_EQ((*all)[static_cast<size_t>(c)].gain, one->gain);
    EXPECT_EQ((*all)[static_cast<size_t>(c)].step, one->step);
    EXPECT_NEAR(one->gain, gains[c], 1e-12);
    EXPECT_NEAR(one->step, steps[c], 1e-12);
  }
  Eigen::VectorXd inside(5);
  inside << 4.0, 2.0, 0.0, 0.0, 0.0;
  EXPECT_FALSE(ScoreTests(Q0, inside, r).has_value());
}

// ---- calibration options and summary ----------------------------------------------------------

TEST(CalibrationOptions, IsValidRejectsEachBadFieldWithItsName) {
  std::string why;
  EXPECT_TRUE(CalibrationOptions{}.IsValid(&why)) << why;
  CalibrationOptions o;
  o.max_iterations = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("max_iterations"), std::string::npos);
  o = {};
  o.nuisance_max_iterations = -1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("nuisance_max_iterations"), std::string::npos);
  o = {};
  o.function_tolerance = 0.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("function_tolerance"), std::string::npos);
  o = {};
  o.relative_step = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("relative_step"), std::string::npos);
  EXPECT_FALSE(o.IsValid(nullptr));
}

TEST(CalibrationSummary, ListsPriorConflictsBeyondThreeSigmaInEitherDirection) {
  CalibrationSummary s;
  s.usable = true;
  s.prior_sd = 0.05;
  s.knobs = {{"C:block", 350.0, 362.0, 0.67, 0.01},
             {"G:block-ambient", 0.5, 0.5 * std::exp(-0.2), -4.0, 0.02},
             {"gain:discharge", 1.0, std::exp(0.15), 3.0, 0.02}};  // exactly 3: not beyond
  EXPECT_EQ(s.PriorConflicts(), (std::vector<std::string>{"G:block-ambient"}));
  const std::string report = s.FullReport();
  EXPECT_NE(report.find("G:block-ambient"), std::string::npos);
  EXPECT_NE(report.find("prior conflict"), std::string::npos);
  EXPECT_EQ(report.find("NOT usable"), std::string::npos);
}

}  // namespace
}  // namespace rlg::diagnosis
