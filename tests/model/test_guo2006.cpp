// The paper's Eq. (2) fits, Eq. (3) SSE and the pair ranking.

#include <gtest/gtest.h>

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <cmath>

#include "model/coefficients_json.h"
#include "model/guo2006.h"
#include "model/pairs.h"
#include "sim/errors.h"

namespace rlg::model {
namespace {

Eigen::Matrix3d TrueA() {
  Eigen::Matrix3d A;
  A << 0.010, 2.0e-4, -3.0e-6,  // a1: °/h per °C
      -0.004, 5.0e-5, 1.0e-6,   // a2: °/h per °C²
      0.300, 2.0e-3, -1.0e-5;   // a3: °/h per °C of gradient
  return A;
}

/// A run that follows Eq. (2) exactly plus white noise of sigma. Temperatures dwell for the
/// B0 window (so B0 is exactly the constant c) and noise starts after it, which makes the
/// model exact and ordinary least squares unbiased with exact standard errors.
sim::Run EquationTwoRun(const std::string& id, double T0, const Eigen::Matrix3d& A, double sigma, uint64_t seed,
                        double hours = 2.0) {
  boost::random::mt19937_64 rng(seed);
  boost::random::normal_distribution<double> normal;
  sim::Run r;
  r.id = id;
  auto& Ti = r.AddColumn("T1");
  auto& Tj = r.AddColumn("T2");
  auto& b = r.AddColumn("bias_dph");
  const Eigen::Vector3d a = A * Eigen::Vector3d(1.0, T0, T0 * T0);
  const double c = 1.0 + 0.01 * T0;
  for (double t = 0.0; t <= hours * 3600.0; t += 1.0) {
    const double s = std::max(0.0, t - 120.0);
    const double ti = T0 + 3.0 * (1.0 - std::exp(-s / 1500.0)) + 0.5 * std::sin(s / 900.0);
    const double tj = ti + 1.2 * (1.0 - std::exp(-s / 400.0));
    const double dT = ti - T0;
    r.t_s.push_back(t);
    Ti.push_back(ti);
    Tj.push_back(tj);
    b.push_back(c + a[0] * dT + a[1] * dT * dT + a[2] * (tj - ti) + (t >= 120.0 ? sigma * normal(rng) : 0.0));
  }
  return r;
}

std::vector<sim::Run> NineAmbients(double sigma) {
  std::vector<sim::Run> runs;
  for (int k = 0; k < 9; ++k) {
    const double T0 = -30.0 + 10.0 * k;
    runs.push_back(EquationTwoRun("run" + std::to_string(k), T0, TrueA(), sigma, 100 + k));
  }
  return runs;
}

std::vector<const sim::Run*> Ptrs(const std::vector<sim::Run>& v) {
  std::vector<const sim::Run*> p;
  for (const auto& r : v) p.push_back(&r);
  return p;
}

TEST(Guo2006, JointFitRecoversKnownCoefficientsWithinTheirStandardErrors) {
  const auto runs = NineAmbients(0.05);
  FitOptions o;
  const Guo2006Coefficients c = FitGuo2006(Ptrs(runs), o);
  const Eigen::Matrix3d A = TrueA();
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      // The model is exact and the noise white, so (A_hat - A) / SE ~ N(0, 1): 4.5 SE leaves a
      // false-failure chance of ~6e-5 over the nine coefficients.
      EXPECT_NEAR(c.A(k, l), A(k, l), 4.5 * c.A_stderr(k, l)) << "A" << k + 1 << l;
      EXPECT_GT(c.A_stderr(k, l), 0.0);
    }
  }
  // Residual RMS is the noise: 65,000 samples estimate sigma to ~0.3 %; 2 % margin.
  EXPECT_NEAR(c.residual_rms_dph, 0.05, 0.02 * 0.05);
  EXPECT_EQ(c.runs.size(), 9u);
  EXPECT_DOUBLE_EQ(c.t10_range_C[0], -30.0);
  EXPECT_DOUBLE_EQ(c.t10_range_C[1], 50.0);
}

TEST(Guo2006, TwoStageFitRecoversKnownCoefficients) {
  const auto runs = NineAmbients(0.05);
  FitOptions o;
  o.method = FitOptions::Method::kTwoStage;
  const Guo2006Coefficients c = FitGuo2006(Ptrs(runs), o);
  const Eigen::Matrix3d A = TrueA();
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 3; ++l) {
      // Stage 2 fits 3 coefficients to 9 per-run values: its standard errors have 6 degrees of
      // freedom, so t_6 tails: |t| > 6 has probability ~1e-3 per coefficient.
      EXPECT_NEAR(c.A(k, l), A(k, l), 6.0 * c.A_stderr(k, l)) << "A" << k + 1 << l;
    }
  }
  EXPECT_EQ(c.method, "two_stage");
}

TEST(Guo2006, NoiselessDataIsFittedExactly) {
  const auto runs = NineAmbients(0.0);
  const Guo2006Coefficients c = FitGuo2006(Ptrs(runs), FitOptions{});
  // Round-off only: the scaled problem has condition number ~1e3 and the data are O(1).
  EXPECT_LT((c.A - TrueA()).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(c.residual_rms_dph, 1e-10);
}

TEST(Guo2006, SseEqualsAHandComputation) {
  // Two runs of four samples; B0 window 2 s = the first two samples.
  Guo2006Coefficients c;
  c.b0_window_s = 2.0;
  c.A << 0.5, 0.0, 0.0,  //
      0.0, 0.0, 0.0,     //
      1.0, 0.0, 0.0;
  std::vector<sim::Run> runs(2);
  const double T1[2][4] = {{10, 10, 11, 12}, {20, 21, 21, 23}};
  const double T2[2][4] = {{10, 11, 11, 13}, {20, 20, 22, 23}};
  const double B[2][4] = {{1.0, 1.2, 1.9, 2.4}, {0.5, 0.3, 1.6, 1.2}};
  for (int r = 0; r < 2; ++r) {
    runs[r].id = "r" + std::to_string(r);
    auto& a = runs[r].AddColumn("T1");
    auto& b = runs[r].AddColumn("T2");
    auto& y = runs[r].AddColumn("bias_dph");
    for (int k = 0; k < 4; ++k) {
      runs[r].t_s.push_back(k);
      a.push_back(T1[r][k]);
      b.push_back(T2[r][k]);
      y.push_back(B[r][k]);
    }
  }
  // Run 0: B0 = 1.1; yhat = 1.1 + 0.5 dT + (T2 - T1) = 1.1, 2.1, 1.6, 3.1
  //   residuals -0.1, -0.9, 0.3, -0.7 -> SSE = 0.01 + 0.81 + 0.09 + 0.49 = 1.40
  // Run 1: B0 = 0.4; yhat = 0.4, 0.4 + 0.5 - 1 = -0.1, 0.4 + 0.5 + 1 = 1.9, 0.4 + 1.5 + 0 = 1.9
  //   residuals 0.1, 0.4, -0.3, -0.7 -> SSE = 0.01 + 0.16 + 0.09 + 0.49 = 0.75
  EXPECT_NEAR(RunSse(c, runs[0]), 1.40, 1e-12);
  EXPECT_NEAR(RunSse(c, runs[1]), 0.75, 1e-12);
}

TEST(Guo2006, OneAmbientCannotIdentifyTheTi0TermsAndSaysWhich) {
  std::vector<sim::Run> runs;
  for (int k = 0; k < 3; ++k) runs.push_back(EquationTwoRun("r" + std::to_string(k), 20.0, TrueA(), 0.05, k));
  try {
    FitGuo2006(Ptrs(runs), FitOptions{});
    FAIL() << "expected NumericalError";
  } catch (const NumericalError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("cannot separate"), std::string::npos) << m;
    for (const char* name : {"A11", "A12", "A21", "A22", "A31", "A32"}) EXPECT_NE(m.find(name), std::string::npos) << m;
    EXPECT_NE(m.find("1 distinct starting temperatures"), std::string::npos) << m;
    EXPECT_NE(m.find("3 or more different ambients"), std::string::npos) << m;
  }
}

TEST(Guo2006, TwoAmbientsCannotIdentifyTheQuadraticTi0Terms) {
  std::vector<sim::Run> runs = {EquationTwoRun("a", 0.0, TrueA(), 0.05, 1), EquationTwoRun("b", 40.0, TrueA(), 0.05, 2)};
  EXPECT_THROW(FitGuo2006(Ptrs(runs), FitOptions{}), NumericalError);
}

TEST(Guo2006, ShortRunsAndMissingChannelsAreInputErrors) {
  std::vector<sim::Run> runs = NineAmbients(0.05);
  FitOptions o;
  o.pair = {"T1", "T4"};
  EXPECT_THROW(FitGuo2006(Ptrs(runs), o), InputError);
  sim::Run shorty = EquationTwoRun("short", 0.0, TrueA(), 0.05, 1, 0.02);  // 72 s
  try {
    InitialBias(shorty, 120.0);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("shorter than the 120 s B0 window"), std::string::npos) << e.what();
  }
}

TEST(Guo2006, CoefficientsSurviveTheJsonRoundTrip) {
  const auto runs = NineAmbients(0.05);
  const Guo2006Coefficients c = FitGuo2006(Ptrs(runs), FitOptions{});
  const nlohmann::json j = ToJson(c);
  EXPECT_EQ(j["model"], "guo2006");
  EXPECT_EQ(j["A"].size(), 3u);
  const Guo2006Coefficients back = CoefficientsFromJson(nlohmann::json::parse(j.dump()), "mem");
  EXPECT_EQ(back.A, c.A);  // JSON doubles round-trip exactly (shortest representation)
  EXPECT_EQ(back.pair, c.pair);
  EXPECT_EQ(back.runs, c.runs);
  nlohmann::json broken = j;
  broken.erase("A");
  EXPECT_THROW(CoefficientsFromJson(broken, "mem"), InputError);
}

TEST(Pairs, PaperCombinationsInThePapersOrder) {
  const auto& m = PaperCombinations();
  ASSERT_EQ(m.size(), 6u);
  const std::vector<std::array<std::string, 2>> expected = {
      {"T1", "T2"}, {"T1", "T4"}, {"T2", "T4"}, {"T3", "T2"}, {"T3", "T4"}, {"T4", "T3"}};
  for (size_t i = 0; i < 6; ++i) {
    EXPECT_EQ(m[i].name, "M" + std::to_string(i + 1));
    EXPECT_EQ(m[i].pair, expected[i]);
  }
}

TEST(Pairs, AllOrderedPairsOfFourChannelsAreTwelveAndNameTheM) {
  sim::Run r;
  for (const char* n : {"T_amb", "T1", "T2", "T3", "T4", "bias_dph"}) r.AddColumn(n);
  const auto all = AllOrderedPairs(r);
  EXPECT_EQ(all.size(), 12u);
  EXPECT_EQ(all.front().name, "M1");
}

TEST(Pairs, TheGeneratingPairWinsOnDataMadeFromIt) {
  // Data made from the (T1, T2) model; a third channel T3 is a smooth function of time that
  // cannot stand in for the gradient.
  std::vector<sim::Run> runs = NineAmbients(0.02);
  for (auto& r : runs) {
    auto& t3 = r.AddColumn("T3");
    for (double t : r.t_s) t3.push_back(r.Column("T1").front() + 0.5 * (1.0 - std::exp(-t / 5000.0)));
  }
  const std::vector<PairCombination> combos = {{"A", {"T1", "T2"}}, {"B", {"T1", "T3"}}, {"C", {"T3", "T2"}}};
  const auto scores = ScorePairs(Ptrs(runs), combos, FitOptions{});
  EXPECT_EQ(BestPair(scores).combination.name, "A");
  // SSE_ave is the mean of the per-run SSEs (Eq. 3).
  double sum = 0.0;
  for (const auto& pr : scores[0].per_run) sum += pr.second;
  EXPECT_NEAR(scores[0].sse_ave, sum / 9.0, 1e-12);
}

}  // namespace
}  // namespace rlg::model
