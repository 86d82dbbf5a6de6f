// Stage 1 of a diagnosis (diagnosis/data/prepare.h): block layout in whole samples, the
// half-empty last block, the noise levels and the CVODE tolerances drawn from them, on
// synthetic records with closed-form answers. Nothing here simulates or fits.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "diagnosis/data/block_times.h"
#include "diagnosis/data/prepare.h"
#include "io/gyro_file.h"
#include "sim/errors.h"
#include "tests/sim/test_helpers.h"

namespace rlg::diagnosis {
namespace {

// ToBlockMeans's formula, mean(q) = q(m) + var(t) q''(m) / 2, is exact for a quadratic in t:
// blocks of uneven sizes and spacing, one-sample blocks (no variance) left as they are.
TEST(ToBlockMeans, IsExactForAQuadraticAndLeavesOneSampleBlocks) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int n : {3, 4, 9, 40}) {
    std::vector<std::vector<double>> samples;  // each block's sample times
    double t = 0.0;
    for (int k = 0; k < n; ++k) {
      const int m = k == 2 ? 1 : 1 + static_cast<int>(20 * u(rng));
      samples.emplace_back();
      for (int i = 0; i < m; ++i) samples.back().push_back(t += 0.5 + u(rng));
    }
    std::vector<BlockTimes> blocks;
    for (const auto& b : samples) blocks.push_back(TimesOf(b, {0, b.size()}));
    auto q_at = [](int row, double x) { return (row + 1.0) + 0.3 * x - (0.02 + 0.01 * row) * x * x; };
    Eigen::MatrixXd q(2, n), want(2, n);
    for (int k = 0; k < n; ++k)
      for (int row = 0; row < 2; ++row) {
        q(row, k) = q_at(row, blocks[static_cast<size_t>(k)].mean);
        double mean = 0.0;
        for (double x : samples[static_cast<size_t>(k)]) mean += q_at(row, x);
        want(row, k) = mean / static_cast<double>(samples[static_cast<size_t>(k)].size());
      }
    const double one_sample = q(0, 2);
    ToBlockMeans(blocks, q);
    // Exact but for round-off: ~1e-13 on values up to ~100 (t up to ~60 s here).
    for (int k = 0; k < n; ++k)
      for (int row = 0; row < 2; ++row) EXPECT_NEAR(q(row, k), want(row, k), 1e-10) << n << " " << k;
    EXPECT_EQ(q(0, 2), one_sample);
  }
}

// Each block is corrected from the values before any correction, of itself and its neighbours
// (the nearest three at a run's ends): the formula written out, bit for bit, on values that are
// not a quadratic, with a block of no variance left as it is.
TEST(ToBlockMeans, CorrectsFromTheValuesBeforeAnyCorrection) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> z(0.0, 1.0);
  for (int n : {3, 4, 5, 17}) {
    std::vector<BlockTimes> blocks;
    double t = 0.0;
    for (int k = 0; k < n; ++k) blocks.push_back({t += 10.0 + std::abs(z(rng)), k == 1 ? 0.0 : 8.0 + z(rng)});
    Eigen::MatrixXd q(3, n);
    for (Eigen::Index i = 0; i < q.size(); ++i) q.data()[i] = z(rng);
    Eigen::MatrixXd want = q;
    const Eigen::MatrixXd before = q;
    for (int k = 0; k < n; ++k) {
      if (blocks[static_cast<size_t>(k)].variance <= 0.0) continue;
      const int c = std::clamp(k, 1, n - 2);
      const double t0 = blocks[static_cast<size_t>(c - 1)].mean, t1 = blocks[static_cast<size_t>(c)].mean,
                   t2 = blocks[static_cast<size_t>(c + 1)].mean;
      want.col(k) += blocks[static_cast<size_t>(k)].variance *
                     (((before.col(c + 1) - before.col(c)) / (t2 - t1) - (before.col(c) - before.col(c - 1)) / (t1 - t0)) /
                      (t2 - t0));
    }
    ToBlockMeans(blocks, q);
    EXPECT_EQ(q, want) << n;
  }
}

/// A run of n samples at t = k dt with the given columns, each filled by f(k).
sim::Run MakeRun(const std::string& id, double dt_s, size_t n,
                 const std::vector<std::pair<std::string, std::function<double(size_t)>>>& columns) {
  sim::Run run;
  run.id = id;
  for (size_t k = 0; k < n; ++k) run.t_s.push_back(static_cast<double>(k) * dt_s);
  for (const auto& [name, f] : columns) {
    std::vector<double>& c = run.AddColumn(name);
    for (size_t k = 0; k < n; ++k) c.push_back(f(k));
  }
  return run;
}

double Constant20(size_t) { return 20.0; }

/// scenarios/gyros/default.toml: sensors T1..T4, no data-driven source.
const sim::GyroConfig& DefaultGyro() {
  static const sim::GyroConfig g = io::LoadGyro(test::SourcePath("scenarios/gyros/default.toml"));
  return g;
}

struct LayoutCase {
  double dt_s;
  double fit_block_s;    ///< dt round(10 s / dt), at least one sample
  int fit_blocks_per_score;  ///< round(100 s / fit block), at least one
};

class BlockLayoutAtPeriod : public ::testing::TestWithParam<LayoutCase> {};

// 0.1, 1 and 10 s data get the 10 s / 100 s blocks asked for; 60 s data one-sample fit
// blocks of 60 s and score blocks of round(100 / 60) = 2 of them, 120 s; 3 s data 9 s and 99 s.
TEST_P(BlockLayoutAtPeriod, FitAndScoreBlocksAreWholeSamples) {
  const LayoutCase c = GetParam();
  const sim::Run run = MakeRun("a", c.dt_s, 200, {{"T1", Constant20}});
  PreparedRun p;
  p.run = &run;
  BlockLayout(p, DiagnoseOptions{});
  // The times are k dt, so the median step and the block lengths carry the round-off of a
  // product and a difference of numbers below 2e4 s: a few ulps, far below 1e-9 relative.
  EXPECT_NEAR(p.sample_period_s, c.dt_s, 1e-9 * c.dt_s);
  EXPECT_NEAR(p.fit_block_s, c.fit_block_s, 1e-9 * c.fit_block_s);
  EXPECT_EQ(p.fit_blocks_per_score, c.fit_blocks_per_score);
  EXPECT_NEAR(p.score_block_s(), c.fit_block_s * c.fit_blocks_per_score, 1e-9 * c.fit_block_s * c.fit_blocks_per_score);
  // Whole samples: a fit block holds an integer number of sample periods.
  const double samples = p.fit_block_s / p.sample_period_s;
  EXPECT_NEAR(samples, std::round(samples), 1e-9);
}

INSTANTIATE_TEST_SUITE_P(Periods, BlockLayoutAtPeriod,
                         ::testing::Values(LayoutCase{0.1, 10.0, 10}, LayoutCase{1.0, 10.0, 10},
                                           LayoutCase{10.0, 10.0, 10}, LayoutCase{60.0, 60.0, 2},
                                           LayoutCase{3.0, 9.0, 11}),
                         [](const auto& info) {
                           std::string s = std::to_string(info.param.dt_s);
                           s = s.substr(0, s.find_last_not_of('0') + 1);  // "0.100000" -> "0.1"
                           if (s.back() == '.') s.pop_back();                  // "60." -> "60"
                           for (char& ch : s)
                             if (ch == '.') ch = '_';
                           return "dt_" + s + "s";
                         });

TEST(Blocks, AHalfEmptyLastBlockIsDropped) {
  // 9000 s at 0.1 s ending with one sample at t = 9000 s: 900 blocks of 100 samples, and the
  // lone last sample (1 of 100 < half) is not a block.
  std::vector<double> t;
  for (size_t k = 0; k <= 90000; ++k) t.push_back(static_cast<double>(k) * 0.1);
  const auto b = Blocks(t, 10.0, 0.1);
  ASSERT_EQ(b.size(), 900u);
  for (const auto& block : b) EXPECT_EQ(block.second - block.first, 100u);
  EXPECT_EQ(b.back().second, 90000u);
}

TEST(Blocks, ALastBlockOfHalfOrMoreIsKept) {
  // 10 s blocks at 1 s: a last block of 5 samples (exactly half) stays, one of 4 goes.
  std::vector<double> t;
  for (size_t k = 0; k < 25; ++k) t.push_back(static_cast<double>(k));
  const auto kept = Blocks(t, 10.0, 1.0);
  ASSERT_EQ(kept.size(), 3u);
  EXPECT_EQ(kept.back(), std::make_pair(size_t{20}, size_t{25}));
  t.pop_back();
  EXPECT_EQ(Blocks(t, 10.0, 1.0).size(), 2u);
}

TEST(Blocks, BlocksOfOneSampleAtCoarsePeriods) {
  // 60 s data with 60 s fit blocks: every sample is its own block, none dropped.
  std::vector<double> t;
  for (size_t k = 0; k < 30; ++k) t.push_back(60.0 * static_cast<double>(k));
  const auto b = Blocks(t, 60.0, 60.0);
  ASSERT_EQ(b.size(), 30u);
  for (size_t i = 0; i < b.size(); ++i) EXPECT_EQ(b[i], std::make_pair(i, i + 1));
}

TEST(BlockMean, IsTheMeanOfTheBlocksSamples) {
  // 1, 2, ..., 10 over samples [2, 7): (3 + 4 + 5 + 6 + 7) / 5 = 5, exact in binary.
  std::vector<double> v;
  for (int k = 1; k <= 10; ++k) v.push_back(k);
  EXPECT_EQ(BlockMean(v, {2, 7}), 5.0);
}

TEST(ScoreBlockNoise, WhiteNoiseOfKnownSigmaGivesSigmaOverRootOfTheScoreBlock) {
  // One hour at 0.1 s (n = 36000) of white noise, sd 3 mK on T1 and 1 mK on T2: the quieter
  // channel decides, sigma / sqrt(1000 samples per 100 s score block).
  const size_t n = 36000;
  std::mt19937_64 rng(11);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<double> e1(n), e2(n);
  for (size_t k = 0; k < n; ++k) e1[k] = unit(rng), e2[k] = unit(rng);
  sim::Trace trace;
  trace.runs.push_back(MakeRun("a", 0.1, n,
                               {{"T1", [&](size_t k) { return 20.0 + 0.003 * e1[k]; }},
                                {"T2", [&](size_t k) { return 20.0 + 0.001 * e2[k]; }}}));
  const auto runs = Prepare(trace, DefaultGyro(), DiagnoseOptions{});
  const double expected = 0.001 / std::sqrt(1000.0);
  // The estimate is s² = mean(d²) / 2 over n - 1 differences d of sd sigma sqrt(2); their
  // squares are correlated at lag one (corr 1/4), so var(s²) = 3 sigma⁴ / (n - 1) and the
  // relative sd of s is sqrt(3 / (n - 1)) / 2 = 0.46 % at n = 36000. 2.5 % is over 5 sd.
  EXPECT_NEAR(ScoreBlockNoise(runs), expected, 0.025 * expected);
}

TEST(ScoreBlockNoise, NoiseFreeDataHasInfiniteNoise) {
  sim::Trace trace;
  trace.runs.push_back(MakeRun("a", 1.0, 100, {{"T1", Constant20}}));
  EXPECT_EQ(ScoreBlockNoise(Prepare(trace, DefaultGyro(), DiagnoseOptions{})),
            std::numeric_limits<double>::infinity());
}

TEST(PointNoise, AStraightLineHasNone) {
  // Slope 0.25 °C/s at whole seconds: every value and second difference is exact in binary,
  // so every second difference is exactly 0 and none is counted.
  std::vector<std::pair<double, double>> pts;
  for (int k = 0; k < 100; ++k) pts.emplace_back(k, 20.0 + 0.25 * k);
  EXPECT_EQ(PointNoise(pts), 0.0);
}

TEST(PointNoise, WhiteNoiseOnARampGivesItsSigma) {
  // A ramp (no second differences of its own) plus white noise of sd 2 mK over 20000 points.
  // The median of |second differences| of sd sigma sqrt(6) has a relative sd of about
  // 1.17 / sqrt(n) = 0.8 % for independent values; neighbouring second differences share
  // samples (correlations -2/3 and 1/6), which at most doubles it. 5 % is over 3 such sd.
  std::mt19937_64 rng(5);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::vector<std::pair<double, double>> pts;
  for (int k = 0; k < 20000; ++k) pts.emplace_back(k, 20.0 + 0.01 * k + noise(rng));
  EXPECT_NEAR(PointNoise(pts), 0.002, 0.05 * 0.002);
}

/// A chamber profile at 1 s points: 20 °C for 2000 s, up at 1 °C/min to 40 °C, 2000 s there,
/// down at 0.5 °C/min to 25 °C and held, plus a slow wander of `wander` °C (period 2500 s).
double Chamber(double t, double wander) {
  double v = 20.0;
  if (t > 2000.0) v = std::min(40.0, 20.0 + (t - 2000.0) / 60.0);
  if (t > 4200.0) v = std::max(25.0, 40.0 - (t - 4200.0) / 120.0);
  return v + wander * std::sin(2.0 * M_PI * t / 2500.0);
}

TEST(NoiseAtEveryPoint, AnExactCurveBetweenCornersHasNone) {
  // 1/60 °C/s is not exact in binary: the ramps' second differences are round-off, 1e-14 of
  // 40 °C, far below 1e-9 of it. PointNoise, which leaves out only exact zeros, measures them
  // and the four corners instead.
  std::vector<std::pair<double, double>> pts;
  for (int k = 0; k <= 9000; ++k) pts.emplace_back(k, Chamber(k, 0.0));
  EXPECT_EQ(NoiseAtEveryPoint(pts), 0.0);
}

TEST(NoiseAtEveryPoint, WhiteNoiseGivesItsSigmaOnAnyCurve) {
  // As PointNoise's test: 5 % is over 3 sd of the median's scatter; the corners and the 4 mK
  // wander's second differences (1e-8 °C) move the median by far less.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::vector<std::pair<double, double>> pts;
  for (int k = 0; k < 20000; ++k) pts.emplace_back(k, Chamber(k, 0.004) + noise(rng));
  EXPECT_NEAR(NoiseAtEveryPoint(pts), 0.002, 0.05 * 0.002);
}

TEST(LoggedAmbientCurve, AnExactRecordKeepsItsCornersWithinTheTolerance) {
  std::vector<std::pair<double, double>> pts;
  for (int k = 0; k <= 9000; ++k) pts.emplace_back(k, Chamber(k, 0.0));
  const double noise = 4e-4;  // score-block noise: the tolerance is at most this
  const sim::Profile curve = LoggedAmbientCurve(pts, noise);
  for (const auto& [t, v] : pts) ASSERT_NEAR(curve.Value(t), v, noise) << "t = " << t;
  EXPECT_LT(curve.Breakpoints().size(), 12u);  // the four corners and the ends, not 9001 points
}

TEST(LoggedAmbientCurve, ANoisyRecordIsSmoothedToWellBelowItsNoise) {
  // 2 mK of white noise per point (the reference generator's chamber sensor) on the chamber
  // profile with a wander from none to 6x the noise. Interpolating the points would be off by
  // the noise itself, 2 mK RMS. The least-squares curve averages each knot over the tens to
  // hundreds of points around it: over 30 points a knot's error is 2 / sqrt(30) ~ 0.37 mK, so
  // an RMS below 0.5 mK (a quarter of the noise) must hold, and the wander must be followed,
  // not flattened (which would leave 0.7 of its amplitude as RMS).
  for (double wander : {0.0, 0.003, 0.006, 0.012}) {
    std::mt19937_64 rng(11);
    std::normal_distribution<double> noise(0.0, 0.002);
    std::vector<std::pair<double, double>> pts;
    for (int k = 0; k <= 9000; ++k) pts.emplace_back(k, Chamber(k, wander) + noise(rng));
    const sim::Profile curve = LoggedAmbientCurve(pts, 6e-4);
    double ss = 0.0, worst = 0.0;
    for (int k = 0; k <= 9000; ++k) {
      const double e = curve.Value(k) - Chamber(k, wander);
      ss += e * e;
      worst = std::max(worst, std::abs(e));
    }
    const double rms = std::sqrt(ss / 9001.0);
    EXPECT_LT(rms, 0.5e-3) << "wander " << wander;
    // Near a corner or a short knot span a knot averages few points: 2.5 sd of one point.
    EXPECT_LT(worst, 5e-3) << "wander " << wander;
    std::printf("wander %.0f mK: RMS error %.3g mK, worst %.3g mK, %zu knots\n", 1e3 * wander, 1e3 * rms,
                1e3 * worst, curve.Breakpoints().size());
  }
}

TEST(LoggedAmbientCurve, ItsStartsStandardErrorIsTheFirstKnotsAndCoversItsError) {
  // A dwell logged with 2 mK of noise: the gyro powers on soaked at the true ambient, which the
  // model knows only through the curve's first value (Model::start's prior). With two knots,
  // the ends of a straight-line fit through n equally spaced points: var = s² (1/n + (x0 -
  // mean)² / Sxx) = s² (4n - 2) / (n (n + 1)), s the record's noise estimate.
  {
    std::mt19937_64 rng(3);
    std::normal_distribution<double> noise(0.0, 0.002);
    std::vector<std::pair<double, double>> pts;
    const int n = 300;
    for (int k = 0; k < n; ++k) pts.emplace_back(k, 20.0 + noise(rng));
    double start_sd = 0.0;
    const sim::Profile curve = LoggedAmbientCurve(pts, 6e-4, &start_sd);
    ASSERT_EQ(curve.Breakpoints().size(), 2u) << "one straight stretch";
    EXPECT_NEAR(start_sd, NoiseAtEveryPoint(pts) * std::sqrt((4.0 * n - 2.0) / (n * (n + 1.0))), 1e-12);
  }
  // And it covers the first value's error as often as it claims, knots placed by the data
  // included (a ramp from t = 100 s): over 400 noise seeds the errors' variance in units of
  // their standard errors is 1 within 3 sd of a 400-sample variance (sqrt(2 / 400) = 7 %).
  double sum = 0.0;
  const int seeds = 400;
  for (int seed = 0; seed < seeds; ++seed) {
    std::mt19937_64 rng(1000 + seed);
    std::normal_distribution<double> noise(0.0, 0.002);
    std::vector<std::pair<double, double>> pts;
    auto truth = [](double t) { return 15.0 + std::max(0.0, t - 100.0) / 60.0; };
    for (int k = 0; k < 600; ++k) pts.emplace_back(k, truth(k) + noise(rng));
    double start_sd = 0.0;
    const sim::Profile curve = LoggedAmbientCurve(pts, 6e-4, &start_sd);
    ASSERT_GT(start_sd, 0.0);
    sum += std::pow((curve.Value(0.0) - truth(0.0)) / start_sd, 2);
  }
  std::printf("start error variance / its standard error squared: %.3f over %d seeds\n", sum / seeds, seeds);
  EXPECT_NEAR(sum / seeds, 1.0, 3.0 * std::sqrt(2.0 / seeds));
}

TEST(LoggedAmbient, TheStartsStandardErrorCoversItsErrorAtSubSecondSamples) {
  // At 0.1 s samples the curve is fitted to 1 s block means and to the first and last raw
  // readings, each of ten times a block mean's variance. Weighted as equals, with the knots
  // placed on them too, the start's standard error claimed too little: the error's variance
  // was 5.8 and 7.2 times it on 100 s and 20 s dwells. Over 4,000 seeds of a 100 s and a 300 s
  // dwell the ratio is 1 within 3 sd of a 4,000-sample variance (sqrt(2 / 4000) = 2.2 %), plus
  // up to 4 % above for the noise estimate's own error, which the standard error takes as
  // known (1 s samples: 1.04 and 1.01 over 10,000 seeds; 0.1 s: 1.04 and 1.04). Shorter
  // stretches add more of it at any period (20 s: 1.25-1.28).
  for (const int seconds : {100, 300}) {
    double sum = 0.0;
    const int seeds = 4000;
    for (int seed = 0; seed < seeds; ++seed) {
      std::mt19937_64 rng(5000 + seed);
      std::normal_distribution<double> noise(0.0, 0.002);
      std::vector<double> t, v;
      for (int k = 0; k < 10 * seconds; ++k) t.push_back(0.1 * k), v.push_back(20.0 + noise(rng));
      double start_sd = 0.0;
      const sim::Profile curve = LoggedAmbient(t, v, 0.1, 4e-4, &start_sd);
      ASSERT_GT(start_sd, 0.0);
      sum += std::pow((curve.Value(0.0) - 20.0) / start_sd, 2);
    }
    std::printf("%d s at 0.1 s: start error variance / its standard error squared %.3f\n", seconds, sum / seeds);
    EXPECT_GT(sum / seeds, 1.0 - 3.0 * std::sqrt(2.0 / seeds)) << seconds << " s";
    EXPECT_LT(sum / seeds, 1.04 + 3.0 * std::sqrt(2.0 / seeds)) << seconds << " s";
  }
}

TEST(InputJumps, AStepBetweenTwoSamplesIsOneAndARampAtAnySamplingIsNone) {
  // The worked example's ambient: 20 °C, a step to 40 °C that the 1800 s sample first shows.
  std::vector<double> step(3600, 20.0);
  for (size_t k = 1800; k < step.size(); ++k) step[k] = 40.0;
  EXPECT_EQ(InputJumps(step, 1e-3), (std::vector<size_t>{1800}));
  // A 1 °C/min ramp sampled every 60 s, with its corners mid-interval (a corner moves one
  // difference by at most a factor of two): no jump.
  std::vector<double> ramp;
  for (int k = 0; k < 200; ++k) ramp.push_back(Chamber(60.0 * k + 17.0, 0.0));
  EXPECT_TRUE(InputJumps(ramp, 1e-3).empty());
  // The same step under 2 mK of noise per sample is found; the noise alone never is (a jump
  // must exceed 10 times a difference's noise: 14 sd of a sample).
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::vector<double> noisy = step, quiet(step.size(), 20.0);
  for (size_t k = 0; k < step.size(); ++k) noisy[k] += noise(rng), quiet[k] += noise(rng);
  EXPECT_EQ(InputJumps(noisy, 1e-3), (std::vector<size_t>{1800}));
  EXPECT_TRUE(InputJumps(quiet, 1e-3).empty());
  // A last digit flipping on a dwell is below min_jump.
  std::vector<double> digit(100, 20.0);
  digit[50] = 20.0001;
  EXPECT_TRUE(InputJumps(digit, 1e-3).empty());
}

TEST(LoggedAmbient, AStepIsTakenAtTheSampleThatFirstShowsItAndARampStaysAPolyline) {
  std::vector<double> t, step;
  for (int k = 0; k < 3600; ++k) t.push_back(k), step.push_back(k < 1800 ? 20.0 : 40.0);
  const sim::Profile a = LoggedAmbient(t, step, 1.0, 4e-4);
  EXPECT_EQ(a.Value(1799.5), 20.0);  // held: the step is not spread over the interval
  EXPECT_EQ(a.Value(1800.0), 40.0);
  EXPECT_EQ(a.Value(0.0), 20.0);
  EXPECT_EQ(a.Value(3599.0), 40.0);
  // The heat an interpolated step would have put in: 10 °C s over the interval; held, the
  // area differs from the true step at 1800 s by the millionth of a second before it only.
  double area = 0.0;
  for (int i = 0; i < 1000; ++i) area += a.Value(1799.0 + (i + 0.5) / 1000.0) / 1000.0;
  EXPECT_NEAR(area, 20.0, 1e-9 + 20.0 * 1e-6);
  // A ramp at 60 s samples is unchanged: its curve goes through every sample.
  std::vector<double> tr, ramp;
  for (int k = 0; k < 200; ++k) tr.push_back(60.0 * k), ramp.push_back(Chamber(60.0 * k + 17.0, 0.0));
  const sim::Profile b = LoggedAmbient(tr, ramp, 60.0, 4e-4);
  for (size_t k = 0; k < tr.size(); ++k) EXPECT_NEAR(b.Value(tr[k]), ramp[k], 4e-4) << tr[k];
}

TEST(SolverForData, TolerancesAreATenthOfTheNoiseOverTheDriftFactor) {
  // 1.5e-4 °C of score-block noise: 0.1 x 1.5e-4 / 1.5e4 = 1e-9 (one rounding each: 1e-12
  // relative is far above that).
  EXPECT_NEAR(SolverForData(1.5e-4).cvode.rtol, 1e-9, 1e-21);
  EXPECT_EQ(SolverForData(1.5e-4).cvode.atol, SolverForData(1.5e-4).cvode.rtol);
  EXPECT_EQ(SolverForData(std::numeric_limits<double>::infinity()).cvode.rtol, 1e-9);
}

TEST(SolverForData, TolerancesGrowMonotonicallyWithTheNoiseWithinTheirClamp) {
  double previous = 0.0;
  for (double noise = 1e-9; noise <= 10.0; noise *= 1.3) {
    const double tol = SolverForData(noise).cvode.rtol;
    EXPECT_GE(tol, previous) << "noise " << noise;
    EXPECT_GE(tol, 1e-10);
    EXPECT_LE(tol, 1e-6);
    previous = tol;
  }
  EXPECT_EQ(SolverForData(1e-9).cvode.rtol, 1e-10);  // below the clamp
  EXPECT_EQ(SolverForData(10.0).cvode.rtol, 1e-6);   // above it
}

TEST(Prepare, FindsTheSensorAndBiasColumnsOfTheGyro) {
  sim::Trace trace;
  trace.runs.push_back(MakeRun("a", 1.0, 100, {{"T3", Constant20}, {"bias_dph", Constant20}, {"T1", Constant20}}));
  const auto runs = Prepare(trace, DefaultGyro(), DiagnoseOptions{});
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].sensor_col, (std::vector<int>{2, -1, 0, -1}));  // T1..T4 of default.toml
  EXPECT_EQ(runs[0].bias_col, 1);
  EXPECT_EQ(runs[0].nuisance, 0);
  EXPECT_FALSE(runs[0].ambient_known);
}

TEST(Prepare, ALoggedPowerIsTakenForAnySourceAndTheGyrosPowerOtherwise) {
  // default.toml: discharge (power_W 0.6) and dither, neither driven by data. A run that logs
  // the discharge's power (a step to 0.8 W at 50 s) is simulated with it.
  sim::Trace trace;
  trace.runs.push_back(MakeRun("a", 1.0, 100,
                               {{"T1", Constant20}, {"P_discharge_W", [](size_t k) { return k < 50 ? 0.6 : 0.8; }}}));
  const auto runs = Prepare(trace, DefaultGyro(), DiagnoseOptions{});
  const auto& sources = DefaultGyro().network.sources;
  const auto discharge = static_cast<size_t>(DefaultGyro().network.FindSource("discharge"));
  const auto dither = static_cast<size_t>(DefaultGyro().network.FindSource("dither"));
  ASSERT_EQ(runs[0].power_logged.size(), sources.size());
  EXPECT_TRUE(runs[0].power_logged[discharge]);
  EXPECT_FALSE(runs[0].power_logged[dither]);
  EXPECT_EQ(runs[0].data_power[discharge].Value(49.0), 0.6);  // zero-order hold, exact values
  EXPECT_EQ(runs[0].data_power[discharge].Value(50.0), 0.8);
  EXPECT_EQ(runs[0].data_power[dither].Value(70.0), sources[dither].power_W);
}

TEST(Prepare, ARunOfFewerThanTwentySamplesIsRefused) {
  sim::Trace trace;
  trace.runs.push_back(MakeRun("a", 1.0, 19, {{"T1", Constant20}}));
  EXPECT_THROW(Prepare(trace, DefaultGyro(), DiagnoseOptions{}), InputError);
}

TEST(Prepare, ARunWithoutAnyChannelOfTheGyroIsRefused) {
  sim::Trace trace;
  trace.runs.push_back(MakeRun("a", 1.0, 100, {{"T9", Constant20}}));
  EXPECT_THROW(Prepare(trace, DefaultGyro(), DiagnoseOptions{}), InputError);
}

TEST(SplitInTime, EvenPiecesAreFittedAndOddOnesHeldOut) {
  sim::Trace trace;
  trace.runs.push_back(MakeRun("a", 1.0, 601, {{"T1", Constant20}}));
  const auto runs = Prepare(trace, DefaultGyro(), DiagnoseOptions{});
  const SplitRun split = SplitInTime(runs[0], 4);
  // 600 s in four pieces of 150 s; the last is open-ended so that t = 600 s counts.
  ASSERT_EQ(split.fit.windows.size(), 2u);
  ASSERT_EQ(split.held.windows.size(), 2u);
  EXPECT_EQ(split.fit.windows[0], std::make_pair(0.0, 150.0));
  EXPECT_EQ(split.held.windows[0], std::make_pair(150.0, 300.0));
  EXPECT_EQ(split.fit.windows[1], std::make_pair(300.0, 450.0));
  EXPECT_EQ(split.held.windows[1].first, 450.0);
  EXPECT_TRUE(split.held.Counts(600.0));
  EXPECT_FALSE(split.fit.Counts(150.0));
  EXPECT_EQ(split.fit.nuisance, 0);
  EXPECT_EQ(split.held.nuisance, 0);
  EXPECT_EQ(split.note, "one run, held out in time: fitted on t = 0-150, 300-450 s, scored on t = 150-300, 450-600 s");
}

}  // namespace
}  // namespace rlg::diagnosis
