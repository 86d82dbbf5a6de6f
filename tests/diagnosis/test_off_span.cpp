// What a column adds to a least-squares fit (diagnosis/statistics/off_span.h): the gain of a
// column of steps, kept as its steps, against the definition row by row; the fallbacks (many
// values, a column near or within the span, NaN, a constant per run) and bad sizes.

#include <gtest/gtest.h>

#include <Eigen/QR>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "diagnosis/statistics/off_span.h"

namespace rlg::diagnosis {
namespace {

using Runs = std::vector<std::vector<double>>;

std::vector<std::pair<const double*, size_t>> View(const Runs& runs) {
  std::vector<std::pair<const double*, size_t>> out;
  for (const auto& r : runs) out.emplace_back(r.data(), r.size());
  return out;
}

/// The definition: x_c centred per run, x = x_c - Q Q' x_c, (x'e)² / x'x; 0 where x'x is at
/// most 1e-12 of x_c'x_c (within the span to round-off).
double GainByDefinition(const Eigen::MatrixXd& Q, const Eigen::VectorXd& e, const Runs& runs) {
  Eigen::VectorXd x = Eigen::VectorXd::Zero(Q.rows());
  Eigen::Index at = 0;
  for (const auto& r : runs) {
    double sum = 0.0;
    for (double v : r) sum += v;
    for (double v : r) x[at++] = v - sum / static_cast<double>(r.size());
  }
  const double raw = x.dot(x);
  x -= Q * (Q.transpose() * x);
  const double xx = x.dot(x);
  if (!(xx > 1e-12 * raw)) return 0.0;
  const double xe = x.dot(e);
  return xe * xe / xx;
}

/// Three runs of 150, 130 and 120 rows; Q an orthonormal basis of `rank` random columns (and of
/// `extra`, when given), e a random residual.
struct Fit {
  Eigen::MatrixXd Q;
  Eigen::VectorXd e;
};
constexpr size_t kRunRows[] = {150, 130, 120};
constexpr Eigen::Index kRows = 400;

Fit RandomFit(std::mt19937_64& rng, int rank, const Eigen::VectorXd* extra = nullptr) {
  std::normal_distribution<double> n01;
  Eigen::MatrixXd X(kRows, rank + (extra ? 1 : 0));
  for (Eigen::Index i = 0; i < X.rows(); ++i)
    for (Eigen::Index j = 0; j < rank; ++j) X(i, j) = n01(rng);
  if (extra) X.col(rank) = *extra;
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(X);
  Fit f{qr.householderQ() * Eigen::MatrixXd::Identity(kRows, X.cols()), Eigen::VectorXd(kRows)};
  for (Eigen::Index i = 0; i < kRows; ++i) f.e[i] = n01(rng);
  return f;
}

/// A mode index in each run: integers from -3 to 3, `hops` steps a run at random rows.
Runs Staircase(std::mt19937_64& rng, int hops) {
  Runs runs;
  std::uniform_int_distribution<int> mode(-3, 3);
  for (size_t n : kRunRows) {
    std::uniform_int_distribution<size_t> row(1, n - 1);
    std::vector<size_t> at;
    for (int h = 0; h < hops; ++h) at.push_back(row(rng));
    std::vector<double> r(n);
    double m = mode(rng);
    for (size_t k = 0; k < n; ++k) {
      for (size_t a : at)
        if (a == k) m = mode(rng);
      r[k] = m;
    }
    runs.push_back(r);
  }
  return runs;
}

Eigen::VectorXd Stacked(const Runs& runs) {
  Eigen::VectorXd v(kRows);
  Eigen::Index at = 0;
  for (const auto& r : runs)
    for (double x : r) v[at++] = x;
  return v;
}

TEST(SpanComplement, AColumnOfStepsGainsWhatTheDefinitionGivesFromItsSteps) {
  std::mt19937_64 rng(7);
  int as_steps = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Fit f = RandomFit(rng, 1 + trial % 8);
    const SpanComplement span(f.Q, f.e);
    const Runs column = Staircase(rng, trial % 12);
    const OffSpan c = span.Project(View(column));
    bool constant = true;  // in every run: the runs' offsets take it, a step each is no use
    for (const auto& r : column)
      for (double v : r) constant = constant && v == r.front();
    EXPECT_EQ(c.steps.empty(), constant) << "trial " << trial;
    as_steps += !c.steps.empty();
    EXPECT_TRUE(c.x.size() == 0 || c.steps.empty());
    EXPECT_LE(c.steps.size(), 3u * (trial % 12 + 1));  // a step per run, and one per hop at most
    // The sums of steps and prefix sums round differently from the rows' sums: 1e-16 of values
    // near 1 over 400 rows, and x'x = x_c'x_c - q'q loses at most 1e6 of that (the rule of
    // Project): 1e-9 relative leaves room.
    const double want = GainByDefinition(f.Q, f.e, column);
    EXPECT_NEAR(span.Gain(c), want, 1e-9 * std::abs(want) + 1e-12) << "trial " << trial;
  }
  EXPECT_GE(as_steps, 150);  // the 17 trials without hops are constant, and a few by chance
}

TEST(SpanComplement, AColumnOfManyValuesIsProjectedRowByRowAsTheDefinitionDoes) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n01;
  for (int trial = 0; trial < 20; ++trial) {
    const Fit f = RandomFit(rng, 5);
    const SpanComplement span(f.Q, f.e);
    Runs column;
    for (size_t n : kRunRows) {
      std::vector<double> r(n);
      for (double& v : r) v = n01(rng);
      column.push_back(r);
    }
    const OffSpan c = span.Project(View(column));
    EXPECT_TRUE(c.steps.empty());
    EXPECT_EQ(c.x.size(), kRows);
    const double want = GainByDefinition(f.Q, f.e, column);
    EXPECT_NEAR(span.Gain(c), want, 1e-12 * want);  // the same operations but for the mean's order
  }
}

TEST(SpanComplement, AColumnWithinOrNearTheSpanIsProjectedRowByRow) {
  std::mt19937_64 rng(13);
  const Runs column = Staircase(rng, 3);
  // Within: the span holds the column itself (centred per run: the span of centred regressors).
  Runs centred = column;
  for (auto& r : centred) {
    double mean = 0.0;
    for (double v : r) mean += v;
    mean /= static_cast<double>(r.size());
    for (double& v : r) v -= mean;
  }
  const Eigen::VectorXd inside = Stacked(centred);
  const Fit f = RandomFit(rng, 4, &inside);
  const SpanComplement span(f.Q, f.e);
  const OffSpan c = span.Project(View(column));
  EXPECT_TRUE(c.within_span);
  EXPECT_EQ(span.Gain(c), 0.0);
  // Near: a span that holds the column but for 1e-4 of a random direction leaves x'x ~1e-8 of
  // x_c'x_c, below the 1e-6 under which steps would lose digits: row by row, as the definition.
  std::normal_distribution<double> n01;
  Eigen::VectorXd nudged = inside;
  for (Eigen::Index i = 0; i < nudged.size(); ++i) nudged[i] += 1e-4 * n01(rng);
  const Fit g = RandomFit(rng, 4, &nudged);
  const SpanComplement near(g.Q, g.e);
  const OffSpan d = near.Project(View(column));
  EXPECT_TRUE(d.steps.empty());
  EXPECT_FALSE(d.within_span);
  const double want = GainByDefinition(g.Q, g.e, column);
  EXPECT_NEAR(near.Gain(d), want, 1e-6 * want);  // x'x of 1e-8 relative: round-off 1e-8 of it
}

TEST(SpanComplement, NaNAConstantPerRunAndNoColumnGainNothing) {
  std::mt19937_64 rng(17);
  const Fit f = RandomFit(rng, 3);
  const SpanComplement span(f.Q, f.e);
  Runs column = Staircase(rng, 2);
  column[1][40] = std::numeric_limits<double>::quiet_NaN();
  const OffSpan c = span.Project(View(column));
  EXPECT_TRUE(c.steps.empty());  // not as steps: NaN is no step's value
  EXPECT_TRUE(c.within_span);    // x'x is NaN: no gain claimed, as row by row always did
  EXPECT_EQ(span.Gain(c), 0.0);
  const Runs constant = {std::vector<double>(150, 2.0), std::vector<double>(130, -1.0), std::vector<double>(120, 0.0)};
  EXPECT_EQ(span.Gain(span.Project(View(constant))), 0.0);  // the runs' offsets take it all
  OffSpan none;
  none.none = true;
  EXPECT_EQ(span.Gain(none), -1.0);
}

TEST(SpanComplement, RefusesAColumnOrResidualOfOtherRows) {
  std::mt19937_64 rng(19);
  const Fit f = RandomFit(rng, 3);
  EXPECT_THROW(SpanComplement(f.Q, Eigen::VectorXd::Zero(kRows - 1)), std::invalid_argument);
  const SpanComplement span(f.Q, f.e);
  const Runs shorter = {std::vector<double>(150, 1.0), std::vector<double>(129, 0.0), std::vector<double>(120, 0.0)};
  EXPECT_THROW(span.Project(View(shorter)), std::invalid_argument);
}

}  // namespace
}  // namespace rlg::diagnosis
