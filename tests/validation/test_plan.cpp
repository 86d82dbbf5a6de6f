// The calibration-protocol planner (validation/plan.h, plan_screen.h, order_statistics.h):
// the order-statistic interval against a direct binomial computation and its coverage over many
// samples; the analytic screen against a Monte Carlo of the linear-Gaussian model it assumes;
// properties (more runs never raise the screen's variance, the Pareto front is non-dominated,
// same seed and any thread count give the same bytes); bad plans; --verify.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "sim/errors.h"
#include "tools/source_dir.h"
#include "validation/order_statistics.h"
#include "validation/plan.h"
#include "validation/plan_screen.h"

namespace rlg::validation {

namespace {

const std::string kPlanDir = rlg::tools::SourcePath("tests/data/plan/");

// P(B <= k) for B ~ Binomial(n, p) by the pmf recursion p_j+1 = p_j (n - j)/(j + 1) p/(1 - p),
// a computation apart from BinomialCdf's log-gamma sum.
double CdfByRecursion(int64_t k, uint64_t n, double p) {
  double pj = std::pow(1.0 - p, static_cast<double>(n)), sum = 0.0;
  for (int64_t j = 0; j <= k && j <= static_cast<int64_t>(n); ++j) {
    sum += pj;
    pj *= static_cast<double>(n - static_cast<uint64_t>(j)) / static_cast<double>(j + 1) * p / (1.0 - p);
  }
  return sum;
}

TEST(OrderStatistics, RanksAreTheBinomialQuantilesForSmallN) {
  for (uint64_t n = 1; n <= 80; ++n) {
    const QuantileRanks r = QuantileInterval(n, 0.95, 0.90);
    // The definition, by the independent CDF: l the largest rank with F(l - 1) <= 0.05, u the
    // smallest with F(u - 1) >= 0.95 (l = 0, u = n + 1 when none).
    uint64_t l = 0, u = n + 1;
    for (uint64_t k = 1; k <= n; ++k)
      if (CdfByRecursion(static_cast<int64_t>(k) - 1, n, 0.95) <= 0.05) l = k;
    for (uint64_t k = n; k >= 1; --k)
      if (CdfByRecursion(static_cast<int64_t>(k) - 1, n, 0.95) >= 0.95) u = k;
    EXPECT_EQ(r.lower, l) << "n = " << n;
    EXPECT_EQ(r.upper, u) << "n = " << n;
    const double cov = (u == n + 1 ? 1.0 : CdfByRecursion(static_cast<int64_t>(u) - 1, n, 0.95)) -
                       (l == 0 ? 0.0 : CdfByRecursion(static_cast<int64_t>(l) - 1, n, 0.95));
    EXPECT_NEAR(r.coverage, cov, 1e-12) << "n = " << n;  // two summations of the same terms
    EXPECT_GE(r.coverage, 0.90 - 1e-12) << "n = " << n;   // the construction's guarantee
  }
  // The header's statement: 59 gyros bound the p95 above at 90 %, 58 do not.
  EXPECT_EQ(QuantileInterval(58, 0.95, 0.90).upper, 59u);
  EXPECT_LE(QuantileInterval(59, 0.95, 0.90).upper, 59u);
  EXPECT_THROW(QuantileInterval(0, 0.95, 0.9), InputError);
}

TEST(OrderStatistics, RanksForALargePopulationAreBinomialCdfsOwn) {
  // QuantileInterval builds its CDF table as one running sum; at 10,000 gyros its ranks and
  // coverage are exactly those BinomialCdf's separate sums give (the same terms in the same
  // order, so equality, not a tolerance). Only the ranks' neighbours are evaluated here.
  const uint64_t n = 10000;
  for (const double q : {0.5, 0.95}) {
    const QuantileRanks r = QuantileInterval(n, q, 0.90);
    ASSERT_GE(r.lower, 1u);
    ASSERT_LE(r.upper, n);
    const auto F = [&](uint64_t k) { return BinomialCdf(static_cast<int64_t>(k), n, q); };
    EXPECT_LE(F(r.lower - 1), 0.05) << "q = " << q;
    EXPECT_GT(F(r.lower), 0.05) << "q = " << q;  // l is the largest such rank
    EXPECT_GE(F(r.upper - 1), 0.95) << "q = " << q;
    EXPECT_LT(F(r.upper - 2), 0.95) << "q = " << q;  // u is the smallest such rank
    EXPECT_EQ(r.coverage, F(r.upper - 1) - F(r.lower - 1)) << "q = " << q;
  }
}

TEST(OrderStatistics, IntervalCoversTheTrueP95AsOftenAsItSays) {
  // 2,000 samples of 100 draws from Exp(1), whose p95 is ln 20. The interval covers it with
  // the exact binomial probability r.coverage (distribution-free, any continuous law).
  const uint64_t n = 100;
  const int reps = 2000;
  const double truth = std::log(20.0);
  const QuantileRanks r = QuantileInterval(n, 0.95, 0.90);
  std::mt19937_64 rng(20261127);
  std::exponential_distribution<double> exp1(1.0);
  int covered = 0;
  for (int k = 0; k < reps; ++k) {
    std::vector<double> v(n);
    for (auto& x : v) x = exp1(rng);
    const auto iv = QuantileIntervalValues(v, 0.95, 0.90);
    if ((!iv.first || *iv.first <= truth) && (!iv.second || truth <= *iv.second)) ++covered;
  }
  const double rate = static_cast<double>(covered) / reps;
  // The count of covering samples is Binomial(2000, coverage): 4 of its standard errors
  // (4 x 0.0064 at coverage ~0.91) is a false alarm once in 16,000 runs.
  const double se = std::sqrt(r.coverage * (1.0 - r.coverage) / reps);
  EXPECT_NEAR(rate, r.coverage, 4.0 * se) << "coverage " << r.coverage;
  RecordProperty("coverage_rate", std::to_string(rate));
  RecordProperty("coverage_stated", std::to_string(r.coverage));
}

TEST(PlanScreen, VarianceEqualsMonteCarloOfTheLinearGaussianModel) {
  // Three runs of 60 samples, three regressors; y = X beta + white noise + a constant per run.
  // The screen's xbar^T J^-1 xbar is the variance of xbar^T (beta_hat - beta) for the GLS fit
  // (the OLS one when there is no run offset); checked against 4,000 fits.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> z(0.0, 1.0);
  const int runs = 3, m = 60, p = 3;
  std::vector<Eigen::MatrixXd> X(runs, Eigen::MatrixXd(m, p));
  for (int r = 0; r < runs; ++r) {
    for (int k = 0; k < m; ++k) {
      const double t = k / 60.0, T = -20.0 + 30.0 * r;
      X[r](k, 0) = t;
      X[r](k, 1) = t * t;
      X[r](k, 2) = t * T / 10.0;
    }
  }
  const Eigen::VectorXd xbar = (Eigen::VectorXd(p) << 0.5, 0.33, 3.0).finished();
  for (double offset_sd : {0.0, 0.4}) {
    const ScreenNoise noise{0.25, offset_sd * offset_sd};
    const std::vector<ScreenNoise> noises(runs, noise);
    const double predicted = CoefficientVariance(InformationMatrix(X, noises), xbar);
    // GLS with each run's Cov = s_w² I + s_o² 1 1^T, written out (not Sherman-Morrison).
    Eigen::MatrixXd A = Eigen::MatrixXd::Zero(p, p);
    std::vector<Eigen::MatrixXd> W(runs);
    for (int r = 0; r < runs; ++r) {
      const Eigen::MatrixXd C = noise.white_var * Eigen::MatrixXd::Identity(m, m) +
                                noise.offset_var * Eigen::MatrixXd::Ones(m, m);
      W[r] = C.inverse();
      A += X[r].transpose() * W[r] * X[r];
    }
    const Eigen::MatrixXd Ainv = A.inverse();
    const int reps = 4000;
    double s2 = 0.0;
    for (int k = 0; k < reps; ++k) {
      Eigen::VectorXd b = Eigen::VectorXd::Zero(p);
      for (int r = 0; r < runs; ++r) {
        const double o = offset_sd * z(rng);
        Eigen::VectorXd e(m);
        for (int i = 0; i < m; ++i) e(i) = std::sqrt(noise.white_var) * z(rng) + o;
        b += X[r].transpose() * W[r] * e;  // beta = 0: beta_hat - beta = A^-1 X^T W e
      }
      const double d = xbar.dot(Ainv * b);
      s2 += d * d;
    }
    const double mc = s2 / reps;
    // A variance estimated from 4,000 Gaussian draws has a relative standard error of
    // sqrt(2 / 4000) = 2.2 %; 4 of them (9 %) is a false alarm once in 16,000 runs.
    EXPECT_NEAR(mc / predicted, 1.0, 4.0 * std::sqrt(2.0 / reps)) << "offset sd " << offset_sd;
  }
}

TEST(PlanScreen, MoreRunsNeverRaiseTheVariance) {
  // Information adds: J(runs + one more) - J(runs) is positive semi-definite, so xbar^T J^-1
  // xbar cannot grow. 200 random designs, each extended by a random run.
  std::mt19937_64 rng(11);
  std::normal_distribution<double> z(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<Eigen::MatrixXd> X;
    for (int r = 0; r < 4; ++r) {
      Eigen::MatrixXd x(20, 4);
      for (int i = 0; i < x.size(); ++i) x(i) = z(rng);
      X.push_back(x);
    }
    const Eigen::VectorXd xbar = Eigen::VectorXd::NullaryExpr(4, [&](Eigen::Index) { return z(rng); });
    const std::vector<ScreenNoise> noise(5, ScreenNoise{0.5, 0.1});
    const double before = CoefficientVariance(InformationMatrix(X, {noise.begin(), noise.begin() + 4}), xbar);
    Eigen::MatrixXd extra(20, 4);
    for (int i = 0; i < extra.size(); ++i) extra(i) = z(rng);
    X.push_back(extra);
    const double after = CoefficientVariance(InformationMatrix(X, noise), xbar);
    EXPECT_LE(after, before * (1.0 + 1e-9)) << "trial " << trial;  // 1e-9: the LDLT's rounding
  }
}

TEST(PlanScreen, MaxAbsNormalQuantileClosedForms) {
  // One term N(0, 1): the 95 % quantile of |Z| is 1.959964 (Phi^-1(0.975)).
  EXPECT_NEAR(MaxAbsNormalQuantile({0.0}, {1.0}, 0.95), 1.959963984540054, 1e-9);
  // Two equal independent terms: (2 Phi(x) - 1)² = 0.95, x = Phi^-1((1 + sqrt 0.95) / 2).
  const double x = MaxAbsNormalQuantile({0.0, 0.0}, {4.0, 4.0}, 0.95);
  EXPECT_NEAR(std::pow(std::erf(x / 2.0 / M_SQRT2), 2), 0.95, 1e-9);
  // No noise: the largest |m|.
  EXPECT_NEAR(MaxAbsNormalQuantile({0.3, -0.5}, {0.0, 0.0}, 0.95), 0.5, 1e-9);
}

TEST(Pareto, FrontIsNonDominatedAndDominatesTheRest) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 100; ++trial) {
    std::vector<double> h(15), p(15);
    for (size_t i = 0; i < h.size(); ++i) {
      h[i] = std::round(50 * u(rng));  // whole hours: ties happen
      p[i] = u(rng);
    }
    const auto front = ParetoFront(h, p);
    auto dominates = [&](size_t a, size_t b) { return h[a] <= h[b] && p[a] <= p[b] && (h[a] < h[b] || p[a] < p[b]); };
    ASSERT_FALSE(front.empty());
    for (size_t i = 0; i < h.size(); ++i) {
      const bool on = std::find(front.begin(), front.end(), i) != front.end();
      bool dominated = false;
      for (size_t j = 0; j < h.size(); ++j) dominated = dominated || dominates(j, i);
      EXPECT_EQ(on, !dominated) << "trial " << trial << " point " << i;
    }
  }
}

class SmallPlan : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    planner_ = new Planner(LoadPlan(kPlanDir + "small.toml"));
    result_ = new PlanResult(planner_->Run(2));
  }
  static void TearDownTestSuite() {
    delete result_;
    delete planner_;
  }
  static Planner* planner_;
  static PlanResult* result_;
};
Planner* SmallPlan::planner_ = nullptr;
PlanResult* SmallPlan::result_ = nullptr;

TEST_F(SmallPlan, CandidatesAndTheirChamberHours) {
  ASSERT_EQ(result_->candidates.size(), 3u);
  // d-optimal-3: three 1 h soaks with 1 h of settling each.
  EXPECT_DOUBLE_EQ(result_->candidates[0].chamber_h, 6.0);
  EXPECT_DOUBLE_EQ(result_->candidates[1].chamber_h, 10.0);
  // heating-ramp: 1 h settling, 60 °C at 1 °C/min, 30 min at the top.
  EXPECT_DOUBLE_EQ(result_->candidates[2].chamber_h, 2.5);
}

TEST_F(SmallPlan, EqTwoOnOnePowerOnIsReportedAsNotFittable) {
  const auto& ramp = result_->candidates[2];
  EXPECT_FALSE(ramp.screen.failure.empty());
  EXPECT_FALSE(ramp.has_numbers());
  EXPECT_FALSE(ramp.meets.has_value());
  EXPECT_FALSE(ramp.pareto);
}

TEST_F(SmallPlan, MoreSoaksNeverRaiseTheScreensVariance) {
  // five-soaks holds d-optimal-3's three soaks (-20, 10, 40 °C) and two more.
  const auto& three = result_->candidates[0].screen;
  const auto& five = result_->candidates[1].screen;
  ASSERT_EQ(three.sd_dph.size(), 2u);
  for (size_t s = 0; s < 2; ++s) EXPECT_LE(five.sd_dph[s], three.sd_dph[s] * (1.0 + 1e-9));  // rounding only
}

TEST_F(SmallPlan, RecommendationIsTheCheapestThatMeetsTheTarget) {
  const auto& c = result_->candidates;
  for (const auto& x : c) {
    if (!x.has_numbers()) continue;
    EXPECT_LE(x.abs_bias_after.median, x.abs_bias_after.p95);
    EXPECT_LE(x.abs_bias_after.p95, x.abs_bias_after.worst);
    ASSERT_TRUE(x.abs_bias_after.p95_lo.has_value());
    EXPECT_LE(*x.abs_bias_after.p95_lo, x.abs_bias_after.p95);
    // 24 gyros cannot bound a p95 above at 90 % (59 are needed): undecided at best.
    EXPECT_FALSE(x.abs_bias_after.p95_hi.has_value());
    EXPECT_NE(x.meets, Meets::kYes);
  }
  EXPECT_FALSE(result_->recommended.has_value());
  EXPECT_NE(result_->reason.find("more gyros would decide"), std::string::npos) << result_->reason;
  EXPECT_FALSE(result_->verify.has_value());
}

TEST(Plan, AutoSelectsPerGyroAndSoaksWithRampsHoldTheRampThatSoaksAloneDoNot) {
  const Planner planner(LoadPlan(kPlanDir + "service.toml"));
  // The screen's model is the polynomial auto selects on the nominal gyro's noisy runs, with
  // the gradient and its product with T1 where the ramps show them.
  const model::FitRequest screened = planner.ScreenedModel(1);
  EXPECT_EQ(screened.model, "poly");
  EXPECT_EQ(screened.beyond_range.value_or(""), "extrapolate");
  EXPECT_NE(std::find(screened.terms.begin(), screened.terms.end(), "T1*(T2-T1)"), screened.terms.end());
  const PlanResult r = planner.Run(2);
  ASSERT_EQ(r.candidates.size(), 2u);
  for (const auto& c : r.candidates) ASSERT_TRUE(c.has_numbers()) << c.name << ": " << c.failure;
  // On the ramp, soaks alone leave the gradient's interaction unfitted; soaks and ramps hold it.
  // A factor of 3 between their p95s on the ramp leaves room for other seeds: measured 0.42
  // against 0.0094 °/h (45 times).
  EXPECT_GT(r.candidates[0].service[1].p95, 3.0 * r.candidates[1].service[1].p95);
  EXPECT_LT(r.candidates[1].abs_bias_after.p95, 0.05);
}

TEST(Plan, SameSeedSameBytesOnAnyThreadCount) {
  const Planner planner(LoadPlan(kPlanDir + "population.toml"));
  const std::string one = PlanJson(planner, planner.Run(1)).dump(2);
  const std::string two = PlanJson(planner, planner.Run(2)).dump(2);
  const std::string three = PlanJson(planner, planner.Run(3)).dump(2);
  EXPECT_EQ(one, two);
  EXPECT_EQ(one, three);
  const auto j = nlohmann::json::parse(one);
  EXPECT_EQ(j["candidates"].size(), 2u);
  EXPECT_TRUE(j["candidates"][0]["p95_abs_bias_after_dph"].is_number());
}

TEST(Plan, ScreenKeepSimulatesTheBestScreenedOnly) {
  PlanSpec spec = LoadPlan(kPlanDir + "small.toml");
  spec.screen_keep = 1;
  const Planner planner(spec);
  const PlanResult r = planner.Run(1);
  // The screen ranks every fittable candidate; the one with the smallest screened p95 is kept.
  // small.toml's first two are fittable; its heating ramp, one power-on, cannot fit Eq. (2).
  ASSERT_EQ(r.candidates.size(), 3u);
  const size_t fittable = 2;
  EXPECT_NE(r.candidates[fittable].screen.failure, "");
  size_t best = 0;
  for (size_t c = 1; c < fittable; ++c)
    if (r.candidates[c].screen.p95_dph < r.candidates[best].screen.p95_dph) best = c;
  for (size_t c = 0; c < r.candidates.size(); ++c) {
    if (c < fittable) {
      EXPECT_GT(r.candidates[c].screen.p95_dph, 0.0) << c;
    }
    EXPECT_EQ(r.candidates[c].simulated, c == best) << c;
    EXPECT_EQ(r.candidates[c].has_numbers(), c == best) << c;
  }
  EXPECT_NE(PlanText(planner, r).find("screened out"), std::string::npos);
}

TEST(Plan, ShardsMergeToThePlanInOnePiece) {
  // Gyros 0..9 and 10..15 apart, on different thread counts, merged in the other order.
  const Planner planner(LoadPlan(kPlanDir + "population.toml"));
  const std::string whole = PlanJson(planner, planner.Run(2)).dump(2);
  const auto a = ShardJson(planner, planner.Simulate(0, 10, 1));
  const auto b = ShardJson(planner, planner.Simulate(10, 6, 2));
  // Through text, as shards travel between machines: the doubles come back to the bit.
  const auto merged = MergeShards(planner, {{"b.json", nlohmann::json::parse(b.dump())}, {"a.json", nlohmann::json::parse(a.dump())}});
  EXPECT_EQ(PlanJson(planner, planner.Conclude(merged, 1)).dump(2), whole);
  EXPECT_THROW(MergeShards(planner, {{"a.json", a}}), InputError);             // gyros 10..15 in no shard
  EXPECT_THROW(MergeShards(planner, {{"a.json", a}, {"a2.json", a}, {"b.json", b}}), InputError);  // twice
  EXPECT_THROW(planner.Conclude(planner.Simulate(0, 10, 1), 1), InputError);   // not every gyro
}

TEST(Plan, VerifyDrawsFreshGyrosAndIsConsistent) {
  // 64 gyros bound the p95 on both sides; a target of 1 °/h is met by any fitted protocol, so
  // the cheapest is recommended and 64 fresh gyros verify it.
  PlanSpec spec = LoadPlan(kPlanDir + "small.toml");
  spec.gyros = 64;
  spec.target_p95_dph = 1.0;
  spec.candidates.resize(1);  // d-optimal-3
  const Planner planner(spec);
  EXPECT_NE(planner.VerifySeed(), spec.seed);
  const PlanResult r = planner.Run(2, 64);
  ASSERT_TRUE(r.recommended.has_value());
  EXPECT_EQ(r.candidates[*r.recommended].name, "d-optimal-3");
  ASSERT_TRUE(r.verify.has_value());
  EXPECT_EQ(r.verify->gyros, 64u);
  // Fresh gyros: gyro 0 of the verification is not gyro 0 of the prediction.
  const auto pred = planner.RunGyro(spec.seed, 0, {0});
  const auto fresh = planner.RunGyro(planner.VerifySeed(), 0, {0});
  EXPECT_NE(pred[0].score, fresh[0].score);
  // Two 90 % intervals of the same p95 from independent samples miss each other far less than
  // once in a hundred; the prediction is honest when they overlap.
  EXPECT_TRUE(r.verify->consistent()) << "realised " << r.verify->realised_p95 << " predicted "
                                    << r.candidates[*r.recommended].abs_bias_after.p95;
  const auto j = PlanJson(planner, r);
  EXPECT_TRUE(j["verify"]["realised_p95_dph"].is_number());
  EXPECT_TRUE(j["verify"]["consistent"].get<bool>());
  EXPECT_EQ(j["verify"]["verdict"], "consistent");
}

TEST(Plan, VerifyIsUndecidedAgainstAnOpenInterval) {
  // 50 gyros leave the realised p95's interval open above, [lo, inf], which overlaps
  // any prediction whose upper end is above lo: that was reported "consistent".
  EXPECT_EQ(DrawsToBound(0.95, kPlanIntervalLevel), 59u);  // 1 - 0.95^59 >= 0.95 (order_statistics.h)
  EXPECT_EQ(QuantileInterval(58, 0.95, kPlanIntervalLevel).upper, 59u);  // open above at 58
  EXPECT_EQ(VerifyVerdict(0.02, 0.03, 0.0417, std::nullopt), Verdict::kInconsistent);  // no overlap, open or not
  EXPECT_EQ(VerifyVerdict(0.02, 0.05, 0.0417, std::nullopt), Verdict::kUndecided);
  EXPECT_EQ(VerifyVerdict(std::nullopt, 0.05, 0.0417, 0.06), Verdict::kUndecided);
  EXPECT_EQ(VerifyVerdict(0.02, 0.05, 0.0417, 0.06), Verdict::kConsistent);
  EXPECT_EQ(VerifyVerdict(0.02, 0.03, 0.0417, 0.06), Verdict::kInconsistent);
  EXPECT_STREQ(VerdictName(Verdict::kConsistent), "consistent");
  EXPECT_STREQ(VerdictName(Verdict::kInconsistent), "inconsistent");
  EXPECT_STREQ(VerdictName(Verdict::kUndecided), "undecided");
  PlanSpec spec = LoadPlan(kPlanDir + "small.toml");
  spec.gyros = 64;
  spec.target_p95_dph = 1.0;
  spec.candidates.resize(1);
  const Planner planner(spec);
  const PlanResult r = planner.Run(2, 50);
  ASSERT_TRUE(r.verify.has_value());
  EXPECT_FALSE(r.verify->realised_hi.has_value());
  EXPECT_EQ(r.verify->verdict, Verdict::kUndecided);
  EXPECT_FALSE(r.verify->consistent());
  const auto j = PlanJson(planner, r);
  EXPECT_FALSE(j["verify"]["consistent"].get<bool>());
  EXPECT_EQ(j["verify"]["verdict"], "undecided");
  EXPECT_EQ(j["verify"]["gyros_needed"], 59);
  const std::string text = PlanText(planner, r);
  EXPECT_NE(text.find(": undecided (an interval open at one end overlaps almost anything: 59 gyros bound the p95's 90 % "
                      "interval on both sides; --verify 59 or more decides)"),
            std::string::npos)
      << text;
}

class BadPlan : public ::testing::Test {
 protected:
  std::string Write(const std::string& name, const std::string& text) {
    const std::string path = (std::filesystem::temp_directory_path() / ("rlg_test_plan_" + name)).string();
    std::ofstream(path) << text;
    files_.push_back(path);
    return path;
  }
  void TearDown() override {
    for (const auto& f : files_) std::filesystem::remove(f);
  }
  std::vector<std::string> files_;
};

std::string ErrorOf(const std::string& path) {
  try {
    LoadPlan(path);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST_F(BadPlan, RefusalsNameTheFileLineAndWhatWasExpected) {
  const std::string unknown = ErrorOf(kPlanDir + "unknown-candidate.toml");
  EXPECT_NE(unknown.find("unknown-candidate.toml:13: key 'name'"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("unknown candidate 'paper-ten-soaks'"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("paper-nine-soaks"), std::string::npos) << unknown;
  const std::string target = ErrorOf(kPlanDir + "no-target.toml");
  EXPECT_NE(target.find("no-target.toml"), std::string::npos) << target;
  EXPECT_NE(target.find("[target] with p95_abs_bias_after_dph"), std::string::npos) << target;
  const std::string same = ErrorOf(kPlanDir + "service-is-calibration.toml");
  EXPECT_NE(same.find("service-is-calibration.toml:12: service run 'soak+10' is also a calibration run of candidate "
                      "'d-optimal-3'"),
            std::string::npos)
      << same;
  const std::string soak_rate = ErrorOf(Write("soak_rate.toml", "gyro = \"" + rlg::tools::SourcePath("scenarios/gyros/default.toml") +
                                                                    "\"\ngyros = 2\n"
                                                                    "[target]\np95_abs_bias_after_dph = 0.01\n"
                                                                    "[[service]]\nid = \"a\"\nstart_C = 60\n"
                                                                    "rate_C_per_min = 1\n[[candidates]]\nname = \"d-optimal-3\"\n"));
  EXPECT_NE(soak_rate.find(":8: key 'rate_C_per_min'"), std::string::npos) << soak_rate;
}

/// A plan of the default gyro with `candidates` (TOML of [[candidates]] tables), span -20 ...
/// +40 °C, 1 h settling, 1 °C/min, 5 s samples, 4 gyros, one service soak at +50 °C.
std::string CyclePlan(const std::string& candidates) {
  return "gyro = \"" + rlg::tools::SourcePath("scenarios/gyros/default.toml") +
         "\"\ngyros = 4\nseed = 5\n[model]\nname = \"px4\"\n[target]\np95_abs_bias_after_dph = 0.01\n"
         "[chamber]\nspan_C = [-20, 40]\nsettle_h = 1\nramp_C_per_min = 1\nsample_period_s = 5\n"
         "[[service]]\nid = \"soak+50\"\nstart_C = 50\nduration_s = 1800\n" +
         candidates;
}

TEST_F(BadPlan, AChamberCycleIsOneRunOnePowerOnAndOneSettling) {
  const PlanSpec p = LoadPlan(Write("cycle.toml", CyclePlan("[[candidates]]\nname = \"two-ramps\"\n"
                                                            "[[candidates]]\nname = \"chamber-cycle\"\n"
                                                            "[[candidates]]\nname = \"own-cycle\"\n"
                                                            "[[candidates.runs]]\ncycle_C = [-20, 40, 0, 10]\n"
                                                            "rate_C_per_min = 2\ndwell_s = 300\nstop_s = 600\n"
                                                            "hold_s = 900\n")));
  ASSERT_EQ(p.candidates.size(), 3u);
  const Candidate &ramps = p.candidates[0], &cycle = p.candidates[1], &own = p.candidates[2];
  ASSERT_EQ(ramps.runs.size(), 2u);
  ASSERT_EQ(cycle.runs.size(), 1u);
  // The same heating and cooling, 30 min at each end, in one power-on: one settling hour less.
  EXPECT_DOUBLE_EQ(ramps.ChamberHours(), 2 * 1.0 + 2 * (3600.0 + 1800.0) / 3600.0);
  EXPECT_DOUBLE_EQ(cycle.ChamberHours(), 1.0 + (3600.0 + 1800.0 + 3600.0 + 1800.0) / 3600.0);
  EXPECT_DOUBLE_EQ(ramps.ChamberHours() - cycle.ChamberHours(), 1.0);
  EXPECT_EQ(cycle.runs[0].id, "cycle-20to+40to-20");
  // One's own: 60 °C up, 40 down, 10 up at 2 °C/min (3,300 s), 300 s before, 600 s at each of
  // the two interior points, 900 s after.
  ASSERT_EQ(own.runs.size(), 1u);
  const ChamberRun& r = own.runs[0];
  EXPECT_EQ(r.id, "cycle-20to+40to+0to+10");
  EXPECT_DOUBLE_EQ(r.duration_s, 300.0 + 3300.0 + 2 * 600.0 + 900.0);
  EXPECT_DOUBLE_EQ(own.ChamberHours(), 1.0 + r.duration_s / 3600.0);
  const sim::RunSpec spec = r.ToRunSpec();
  // Corners: (300, -20), (2100, 40), (2700, 40), (3900, 0), (4500, 0), (4800, 10), then held.
  const std::vector<std::pair<double, double>> expected = {{0, -20},   {300, -20}, {1200, 10}, {2100, 40},
                                                           {2700, 40}, {3300, 20}, {3900, 0},  {4500, 0},
                                                           {4800, 10}, {5700, 10}};
  for (const auto& [t, v] : expected) EXPECT_NEAR(spec.ambient.Value(t), v, 1e-9) << "t = " << t;  // exact corners
  EXPECT_EQ(spec.duration_s, r.duration_s);
  EXPECT_NE(r.Conditions(), cycle.runs[0].Conditions());
}

TEST_F(BadPlan, AChamberCycleCandidateIsSimulatedFittedAndScored) {
  // The cycle is fitted like any run: PX4's model on the one power-on gives numbers, and the
  // plan charges it one settling.
  const Planner planner(LoadPlan(Write("cycle_run.toml", CyclePlan("[[candidates]]\nname = \"chamber-cycle\"\n"))));
  const PlanResult result = planner.Run(2);
  ASSERT_EQ(result.candidates.size(), 1u);
  const auto& c = result.candidates[0];
  EXPECT_TRUE(c.has_numbers()) << c.failure;
  EXPECT_DOUBLE_EQ(c.chamber_h, 1.0 + 3.0);
}

TEST_F(BadPlan, AMalformedChamberCycleIsRefusedWithFileLineAndWhatWasExpected) {
  // cycle_C is on line 20 of the file: 16 lines of CyclePlan, then [[candidates]], name, [[candidates.runs]].
  const auto refused = [&](const std::string& name, const std::string& run) {
    return ErrorOf(Write(name, CyclePlan("[[candidates]]\nname = \"c\"\n[[candidates.runs]]\n" + run)));
  };
  const std::string monotone = refused("monotone.toml", "cycle_C = [-20, 0, 40]\nrate_C_per_min = 1\n");
  EXPECT_NE(monotone.find("monotone.toml:20: key 'cycle_C'"), std::string::npos) << monotone;
  EXPECT_NE(monotone.find("reversing at least once"), std::string::npos) << monotone;
  const std::string two = refused("two.toml", "cycle_C = [-20, 40]\nrate_C_per_min = 1\n");
  EXPECT_NE(two.find("key 'cycle_C'"), std::string::npos) << two;
  const std::string equal = refused("equal.toml", "cycle_C = [-20, 40, 40, -20]\nrate_C_per_min = 1\n");
  EXPECT_NE(equal.find("points 2 and 3 are both 40 °C: a hold at a point is stop_s"), std::string::npos) << equal;
  const std::string hot = refused("hot.toml", "cycle_C = [-20, 400, -20]\nrate_C_per_min = 1\n");
  EXPECT_NE(hot.find("400 °C is outside the chamber's"), std::string::npos) << hot;
  const std::string both = refused("both.toml", "cycle_C = [-20, 40, -20]\nstart_C = -20\nrate_C_per_min = 1\n");
  EXPECT_NE(both.find("key 'start_C'"), std::string::npos) << both;
  EXPECT_NE(both.find("give one or the other"), std::string::npos) << both;
  const std::string no_rate = refused("no_rate.toml", "cycle_C = [-20, 40, -20]\n");
  EXPECT_NE(no_rate.find("rate_C_per_min"), std::string::npos) << no_rate;
  const std::string stop = refused("stop.toml", "start_C = -20\nend_C = 40\nrate_C_per_min = 1\nstop_s = 60\n");
  EXPECT_NE(stop.find("key 'stop_s'"), std::string::npos) << stop;
  EXPECT_NE(stop.find("chamber cycle"), std::string::npos) << stop;
  const std::string typo = refused("typo.toml", "cycle_C = [-20, 40, -20]\nrate_C_per_min = 1\nstop_ss = 60\n");
  EXPECT_NE(typo.find("unknown key 'stop_ss'"), std::string::npos) << typo;
  EXPECT_NE(typo.find("did you mean 'stop_s'"), std::string::npos) << typo;
}

}  // namespace

}  // namespace rlg::validation
