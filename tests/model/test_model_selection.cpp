// auto (model/model_selection.h): forward selection on blocked cross-validation inside the
// training data. On data made with a hysteresis term it takes that term; on the same data made
// without it, it adds no term. Each over 20 seeds, with the rate printed and held to a floor.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

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
  if (with_hysteresis) terms.push_back({TermKind::kHysteresis, "", 0.0, 3.0});
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
  // in 19 of these 20 and 58 of 60 datasets; 18 leaves room for one more miss.
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
  // No spurious term in these 20 nor in 60 datasets; one of 20 (5 %) is allowed, the rate a
  // selection rule may be expected to err at.
  EXPECT_GE(none, kSeeds - 1);
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

}  // namespace
}  // namespace rlg::model
