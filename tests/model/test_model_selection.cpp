// auto (model/model_selection.h): a stepwise search of a library of terms scored by
// cross-validation from sufficient statistics. The Gram matrices' score equals fitting and
// scoring each fold on the samples; on data made with a hysteresis term, or with the
// temperature x gradient product of the Langmuir term, it takes that term, and on the same data
// made without it, it does not. Each over 20 seeds, with the rate printed and held to a floor.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fmt/format.h>
#include <limits>
#include <string>
#include <vector>

#include "model/gram_cv.h"
#include "model/model_selection.h"
#include "sim/errors.h"
#include "tests/model/poly_truth.h"

namespace rlg::model {
namespace {

/// One chamber cycle (1 h at 2 s), a cubic (fitted offset) with or without a hysteresis loop
/// of w = 3 °C whose two branches lie 0.2 °/h apart (gamma w = 0.2: twice the noise's sd),
/// and AR(1) noise of 0.05 °/h with an 18 s correlation time.
PolyModel AutoOn(bool with_hysteresis, uint64_t seed) {
  sim::Run run = CycleRun("cycle");
  const std::vector<const sim::Run*> runs{&run};
  std::vector<PolyTerm> terms;
  if (with_hysteresis) terms.push_back({TermKind::kHysteresis, "", 0.0, 3.0, {}});
  const PolySpec spec = SpecFor(runs, 3, OffsetRule::kFitted, terms);
  Eigen::VectorXd beta(with_hysteresis ? 5 : 4);
  beta.head(4) << 30.0, 1.5, -0.02, 3e-4;
  if (with_hysteresis) beta[4] = 0.2 / 3.0;
  boost::random::mt19937_64 rng(seed);
  DrawBias(run, spec, beta, 0.0, Ar1{0.05, 9.0}, rng);
  return FitAuto(runs, AutoOptions{});
}

bool Has(const PolyModel& m, TermKind kind) {
  return std::any_of(m.spec.terms.begin(), m.spec.terms.end(), [&](const PolyTerm& t) { return t.kind == kind; });
}

constexpr int kSeeds = 20;

TEST(AutoSelection, TakesTheHysteresisTermOfDataMadeWithOne) {
  int taken = 0, cubic = 0;
  for (int s = 0; s < kSeeds; ++s) {
    const PolyModel m = AutoOn(true, 100 + static_cast<uint64_t>(s));
    taken += Has(m, TermKind::kHysteresis) ? 1 : 0;
    cubic += m.spec.order == 3 ? 1 : 0;
    ASSERT_TRUE(m.selection.has_value());
    EXPECT_FALSE(m.selection->steps.empty());
  }
  std::printf("hysteresis taken in %d of %d datasets made with it; order 3 chosen in %d\n", taken, kSeeds, cubic);
  // The loop is twice the noise's sd (it lowers the score's mean square by about 80 %): taken
  // in 18 of these 20 and 55 of 60 datasets (seeds 100-159; the misses chose a lag, its twin
  // on one cycle): 18 holds what was measured.
  EXPECT_GE(taken, kSeeds - 2);
}

TEST(AutoSelection, AddsNoTermToDataMadeWithoutOne) {
  int none = 0, cubic = 0;
  for (int s = 0; s < kSeeds; ++s) {
    const PolyModel m = AutoOn(false, 200 + static_cast<uint64_t>(s));
    none += m.spec.terms.empty() ? 1 : 0;
    cubic += m.spec.order == 3 ? 1 : 0;
  }
  std::printf("no term added in %d of %d datasets made without one; order 3 chosen in %d\n", none, kSeeds, cubic);
  // A term added in 2 of these 20 and 3 of 60 datasets (seeds 200-259): 5 %, the rate the
  // selection's one-sided 95 % test may be expected to err at (model/model_selection.h). 18
  // holds what was measured; a rule that errs more often fails.
  EXPECT_GE(none, kSeeds - 2);
}

// Every term of the library is tried at the order the search ends on, beside the terms taken
// there: on a quadratic with a rate term and no loop (`fit --model auto --terms rate hysteresis`),
// a model of the selected order with the selected terms plus hysteresis is among those scored,
// so that leaving it out is the data's verdict, not the search's order of moves.
TEST(AutoSelection, TriesEveryTermAtTheSelectedOrder) {
  sim::Run run = CycleRun("cycle");
  const std::vector<const sim::Run*> runs{&run};
  const PolySpec spec = SpecFor(runs, 2, OffsetRule::kFitted, {PolyTerm{TermKind::kRate, "", 0.0, 0.0, {}}});
  Eigen::VectorXd beta(4);
  beta << 30.0, 1.5, -0.02, 2.0;  // 2 °/h per °C/min: the cycle's up to 4 °C/min make it 8 °/h
  boost::random::mt19937_64 rng(11);
  DrawBias(run, spec, beta, 0.0, Ar1{0.05, 9.0}, rng);
  AutoOptions options;
  options.candidate_terms = {"rate", "hysteresis"};
  const PolyModel m = FitAuto(runs, options);
  ASSERT_TRUE(m.selection.has_value());
  ASSERT_TRUE(Has(m, TermKind::kRate)) << m.spec.Describe();
  const std::string order = fmt::format("order {}, ", m.spec.order);
  const bool tried = std::any_of(m.selection->visited.begin(), m.selection->visited.end(), [&](const SelectionStep& st) {
    if (st.candidate.rfind(order, 0) != 0 || st.candidate.find("hysteresis") == std::string::npos) return false;
    return std::all_of(m.spec.terms.begin(), m.spec.terms.end(),
                       [&](const PolyTerm& t) { return st.candidate.find(t.Name()) != std::string::npos; });
  });
  EXPECT_TRUE(tried) << "selected " << m.spec.Describe() << "; no model of its order with its terms and hysteresis scored";
  EXPECT_FALSE(Has(m, TermKind::kHysteresis)) << m.spec.Describe();
}

TEST(AutoSelection, TheOrderIsTheSmallestThatNoHigherOrderBeats) {
  // Mean squares per order over four folds: order 2 beats 1 by 50 % in every fold; 3 is 5 %
  // lower than 2 (under the 10 % margin); 4 is 20 % lower than 2 overall but in two folds only.
  auto cv = [](std::vector<double> fold_ms) {
    CvScore s;
    double sum = 0.0;
    for (double v : fold_ms) sum += v;
    s.rms = std::sqrt(sum / static_cast<double>(fold_ms.size()));
    s.fold_ms = std::move(fold_ms);
    return s;
  };
  std::vector<CvScore> by_order = {cv({2, 2, 2, 2}), cv({1, 1, 1, 1}), cv({0.95, 0.95, 0.95, 0.95}),
                                   cv({0.3, 0.3, 1.1, 1.5}), cv({1.2, 1.2, 1.2, 1.2})};
  EXPECT_EQ(SmallestUnbeatenOrder(by_order, 0.10), 2);
  by_order[1].rms = std::numeric_limits<double>::infinity();  // order 2 could not be fitted
  EXPECT_EQ(SmallestUnbeatenOrder(by_order, 0.10), 3);
  for (auto& s : by_order) s.rms = std::numeric_limits<double>::infinity();
  EXPECT_EQ(SmallestUnbeatenOrder(by_order, 0.10), 0);
}

TEST(AutoSelection, NeverHoldsOutInterleavedSamplesFoldsAreContiguousPieces) {
  sim::Run a = CycleRun("a"), b = CycleRun("b", 5.0);
  const std::vector<RowMask> folds = BlockFolds({&a, &b}, 8);
  ASSERT_EQ(folds.size(), 8u);
  for (size_t k = 0; k < folds.size(); ++k) {
    for (const auto& mask : folds[k]) {
      // Held-out samples (0) form one stretch: the mask changes value at most twice.
      int changes = 0;
      for (size_t i = 1; i < mask.size(); ++i) changes += mask[i] != mask[i - 1] ? 1 : 0;
      EXPECT_LE(changes, 2) << "fold " << k;
      EXPECT_NEAR(std::count(mask.begin(), mask.end(), 0), mask.size() / 8.0, 1.0) << "fold " << k;
    }
  }
  EXPECT_THROW(BlockFolds({&a}, 1), InputError);
}

/// The soaks and ramps of a calibration: warm-ups at -30, 10 and 50 °C, a heating and a cooling
/// ramp at 1 °C/min and one at 0.5 °C/min, 2 h each at 10 s.
std::vector<sim::Run> Calibration() {
  return {ChamberRun("soak-30", -30, -30, 0, 10.0), ChamberRun("soak+10", 10, 10, 0, 10.0),
          ChamberRun("soak+50", 50, 50, 0, 10.0),   ChamberRun("up", -20, 40, 1.0, 10.0),
          ChamberRun("down", 45, -15, -1.0, 10.0),  ChamberRun("up-slow", 0, 30, 0.5, 10.0)};
}

/// The bias c0 + quadratic in T1 + k (T2 - T1) (+ k' T1 (T2 - T1): the Langmuir term's
/// temperature dependence) + AR(1) noise of 0.01 °/h with a 60 s correlation time.
PolyModel AutoOnCalibration(bool interaction, uint64_t seed, std::vector<sim::Run>& runs) {
  runs = Calibration();
  std::vector<const sim::Run*> ptrs;
  for (const auto& r : runs) ptrs.push_back(&r);
  std::vector<PolyTerm> terms{{TermKind::kGradient, "T2", 0.0, 0.0, {}}};
  if (interaction) terms.push_back(*ParseTerm("T1*(T2-T1)", "T1", nullptr));
  PolySpec spec = SpecFor(ptrs, 2, OffsetRule::kFitted, terms, 20.0);
  spec.extrapolate = true;
  Eigen::VectorXd beta(interaction ? 5 : 4);
  beta.head(4) << 0.9, 0.006, -8e-5, 0.45;
  if (interaction) beta[4] = 0.45 * 0.004;  // the default gyro's c_T k_g (docs/physics.md)
  boost::random::mt19937_64 rng(seed);
  for (auto& r : runs) DrawBias(r, spec, beta, 0.0, Ar1{0.01, 6.0}, rng);
  return FitAuto(ptrs, AutoOptions{});
}

bool HasTerm(const PolyModel& m, const std::string& name) {
  return std::any_of(m.spec.terms.begin(), m.spec.terms.end(), [&](const PolyTerm& t) { return t.Name() == name; });
}

TEST(AutoSelection, TakesTheTemperatureTimesGradientTermOfDataMadeWithIt) {
  int taken = 0;
  for (int s = 0; s < kSeeds; ++s) {
    std::vector<sim::Run> runs;
    const PolyModel m = AutoOnCalibration(true, 300 + static_cast<uint64_t>(s), runs);
    taken += HasTerm(m, "T1*(T2-T1)") ? 1 : 0;
    EXPECT_TRUE(m.spec.extrapolate);
    ASSERT_TRUE(m.selection.has_value());
    EXPECT_EQ(m.selection->folds, 6);  // six runs: each held out whole
    if (s == 0) {
      for (const auto& st : m.selection->steps) std::printf("  %-48s %.5f  %s\n", st.note.c_str(), st.cv_rms_dph, st.candidate.c_str());
    }
  }
  std::printf("T1*(T2-T1) taken in %d of %d datasets made with it\n", taken, kSeeds);
  // The product moves the bias by ~0.1 °/h over the ramps, ten times the noise: taken in 20 of
  // these 20 and 60 of 60 (seeds 300-359); one miss is allowed for the selection's own noise.
  EXPECT_GE(taken, kSeeds - 1);
}

TEST(AutoSelection, DoesNotTakeTheProductWhereTheBiasHasNone) {
  int none = 0;
  for (int s = 0; s < kSeeds; ++s) {
    std::vector<sim::Run> runs;
    const PolyModel m = AutoOnCalibration(false, 400 + static_cast<uint64_t>(s), runs);
    none += HasTerm(m, "T1*(T2-T1)") ? 0 : 1;
  }
  std::printf("T1*(T2-T1) left out in %d of %d datasets made without it\n", none, kSeeds);
  // Left out in 20 of these 20 and 60 of 60 (seeds 400-459); one of 20 (5 %) is the rate the
  // selection's test may be expected to err at.
  EXPECT_GE(none, kSeeds - 1);
}

TEST(AutoSelection, RecordsItsPathAndEveryModelItScored) {
  std::vector<sim::Run> runs;
  const PolyModel m = AutoOnCalibration(true, 7, runs);
  ASSERT_TRUE(m.selection.has_value());
  const auto& steps = m.selection->steps;
  ASSERT_GE(steps.size(), 3u);
  EXPECT_EQ(steps.front().note, "start");
  EXPECT_EQ(steps.back().note.rfind("selected", 0), 0u);
  EXPECT_GT(m.selection->visited.size(), steps.size());
  for (const auto& st : m.selection->visited) EXPECT_GT(st.parameters, 0);
  // The selected model is no larger than the lowest score's by more than the rule allows: its
  // score lies within the visited ones.
  double lowest = std::numeric_limits<double>::infinity();
  for (const auto& st : m.selection->visited) lowest = std::min(lowest, st.cv_rms_dph);
  EXPECT_GE(steps.back().cv_rms_dph, lowest);
}

/// The Gram matrices' score against fitting every fold on its samples and scoring the held-out
/// ones: the same numbers to round-off, with both offsets and both kinds of fold.
TEST(GramCv, EqualsFittingAndScoringEachFoldOnTheSamples) {
  std::vector<sim::Run> runs;
  AutoOnCalibration(true, 11, runs);
  std::vector<const sim::Run*> ptrs;
  for (const auto& r : runs) ptrs.push_back(&r);
  std::vector<PolyTerm> terms{{TermKind::kGradient, "T2", 0.0, 0.0, {}}, *ParseTerm("T1*(T2-T1)", "T1", nullptr)};
  PolySpec spec = SpecFor(ptrs, 2, OffsetRule::kFitted, terms);
  spec.extrapolate = true;
  for (const bool loro : {true, false}) {
    for (const OffsetRule offset : {OffsetRule::kFitted, OffsetRule::kPowerOn}) {
      const std::vector<RowMask> folds = loro ? RunFolds(ptrs) : BlockFolds(ptrs, 4);
      // The reference: per fold, the least squares on the used samples (QR) and the sum of
      // squares of the held-out ones, all referred to each run's B0 window for power_on.
      PolySpec s = spec;
      s.offset = offset;
      const PolyRegressors g(s);
      const Design all = BuildDesign(ptrs, g);
      std::vector<double> expected;
      double total = 0.0;
      for (const RowMask& mask : folds) {
        std::vector<Eigen::Index> train, held;
        Eigen::Index at = 0;
        for (size_t r = 0; r < ptrs.size(); ++r)
          for (size_t k = 0; k < ptrs[r]->size(); ++k, ++at) (mask[r][k] ? train : held).push_back(at);
        Eigen::MatrixXd X(static_cast<Eigen::Index>(train.size()), all.X.cols());
        Eigen::VectorXd y(X.rows());
        for (size_t i = 0; i < train.size(); ++i) {
          X.row(static_cast<Eigen::Index>(i)) = all.X.row(train[i]);
          y[static_cast<Eigen::Index>(i)] = all.y[train[i]];
        }
        const Eigen::VectorXd beta = X.colPivHouseholderQr().solve(y);
        double sse = 0.0;
        for (Eigen::Index i : held) sse += std::pow(all.y[i] - all.X.row(i).dot(beta), 2);
        expected.push_back(sse);
        total += sse;
      }
      // The same through GramCv: the library is the spec's own columns (constant, T1, T1^2,
      // gradient, product), each run's pieces as the folds cut them.
      std::vector<RunFoldGram> pieces;
      std::vector<Eigen::VectorXd> means;
      PolySpec lib = spec;  // fitted: column 0 the constant
      const PolyRegressors lg(lib);
      const Design raw = BuildDesign(ptrs, lg);
      Eigen::Index at = 0;
      for (size_t r = 0; r < ptrs.size(); ++r) {
        const auto n = static_cast<Eigen::Index>(ptrs[r]->size());
        Eigen::MatrixXd Z(n, raw.X.cols() + 1);
        Z << raw.X.middleRows(at, n), raw.y.segment(at, n);
        at += n;
        Eigen::Index window = 0;
        while (ptrs[r]->t_s[static_cast<size_t>(window)] < 120.0) ++window;
        means.push_back(Z.topRows(window).colwise().mean().transpose());
        for (size_t k = 0; k < folds.size(); ++k) {
          RunFoldGram p;
          p.run = r;
          p.fold = k;
          Eigen::MatrixXd G = Eigen::MatrixXd::Zero(Z.cols(), Z.cols());
          for (Eigen::Index i = 0; i < n; ++i)
            if (!folds[k][r][static_cast<size_t>(i)]) G += Z.row(i).transpose() * Z.row(i);
          p.gram = G;
          if (G(0, 0) > 0.0) pieces.push_back(p);
        }
      }
      const GramCv cv(pieces, means, folds.size(), offset == OffsetRule::kPowerOn);
      std::vector<int> columns = offset == OffsetRule::kFitted ? std::vector<int>{0, 1, 2, 3, 4} : std::vector<int>{1, 2, 3, 4};
      const CvScore got = cv.Score(columns);
      ASSERT_EQ(got.fold_sse.size(), expected.size());
      for (size_t k = 0; k < expected.size(); ++k) {
        // Normal equations on unit-scaled columns against QR: ~1e-9 relative at this
        // conditioning (a quadratic and a product of temperatures over 80 °C).
        EXPECT_NEAR(got.fold_sse[k], expected[k], 1e-7 * total + 1e-12) << (loro ? "runs" : "pieces") << " fold " << k;
      }
    }
  }
}

/// A score from its folds' sums of squares (one sample each, so mean squares are the sums).
CvScore Folds(std::vector<double> sse) {
  CvScore s;
  double sum = 0.0;
  for (double v : sse) sum += v;
  s.rms = std::sqrt(sum / static_cast<double>(sse.size()));
  s.fold_ms = sse;
  s.fold_sse = std::move(sse);
  return s;
}

TEST(SelectionBeats, EachOfItsTestsOnFoldsMadeForIt) {
  // Below the 10 % margin nothing beats: 5 % lower in every fold.
  EXPECT_FALSE(SelectionBeats(Folds({0.95, 0.95, 0.95, 0.95, 0.95}), Folds({1, 1, 1, 1, 1}), 0.10, 0.95, true));
  // The sign test: lower in all 5 of 5 folds (P = 1/32 < 5 %), by ratios too uneven for the
  // t-test, the total under the quarter and the differences' spread wide.
  const CvScore a = Folds({1.0, 1.0, 1.0, 1.0, 10.0}), b = Folds({0.99, 0.9, 0.5, 0.98, 4.0});
  EXPECT_TRUE(SelectionBeats(b, a, 0.10, 0.95, false));
  // 4 of 5 lower and one a little higher: neither the sign test (P = 6/32) nor the t-test.
  const CvScore b4 = Folds({0.99, 0.9, 0.5, 1.02, 4.0});
  EXPECT_FALSE(SelectionBeats(b4, a, 0.10, 0.95, false));
  // The same folds as whole runs: the sum of the differences (6.59) beyond one standard error.
  EXPECT_TRUE(SelectionBeats(b4, a, 0.10, 0.95, true));
  // The t-test of log ratios: 30 % lower in eight folds and 5 % higher in two (the sign test's
  // P = 56/1024 misses 5 %; the mean over the sd of the ratios does not).
  const CvScore c = Folds({1, 1, 1, 1, 1, 1, 1, 1, 1, 1}),
                d = Folds({0.7, 0.7, 0.7, 0.7, 0.7, 0.7, 0.7, 0.7, 1.05, 1.05});
  EXPECT_TRUE(SelectionBeats(d, c, 0.10, 0.95, false));
  // A quarter of the mean square beats whatever the folds say (here one fold higher).
  EXPECT_TRUE(SelectionBeats(Folds({0.1, 0.1, 2.0}), Folds({10, 10, 1.0}), 0.10, 0.95, false));
  // Nothing beats a score of zero, nor itself.
  EXPECT_FALSE(SelectionBeats(Folds({0, 0}), Folds({0, 0}), 0.10, 0.95, true));
  EXPECT_FALSE(SelectionBeats(a, a, 0.10, 0.95, true));
}

TEST(AutoSelection, RunFoldsHoldOutEachRunWhole) {
  sim::Run a = CycleRun("a"), b = CycleRun("b", 5.0), c = CycleRun("c", 3.0);
  const std::vector<RowMask> folds = RunFolds({&a, &b, &c});
  ASSERT_EQ(folds.size(), 3u);
  for (size_t k = 0; k < 3; ++k)
    for (size_t r = 0; r < 3; ++r)
      for (char used : folds[k][r]) EXPECT_EQ(used, r == k ? 0 : 1);
  EXPECT_EQ(SelectionFolds({&a, &b, &c}, 8, 3).size(), 3u);
  EXPECT_EQ(SelectionFolds({&a, &b}, 8, 3).size(), 8u);
}

}  // namespace
}  // namespace rlg::model
