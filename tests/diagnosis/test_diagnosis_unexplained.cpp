// Stage 7 (diagnosis/statistics/unexplained.h): the noise estimate, the correlation, and which
// channel-runs are reported as unexplained, on synthetic residuals with known answers.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "diagnosis/statistics/unexplained.h"

namespace rlg::diagnosis {
namespace {

TEST(WhiteNoiseSd, QuantizedNoiseOnARampWithCornersGivesItsSigma) {
  // 2 mK of noise read in 1 mK steps (the reference generator's sensors) on 0 / ramp / 0 at
  // 10 s samples: the quantization adds q²/12 of variance, sd sqrt(4 + 1/12) = 2.02 mK. 3000
  // samples: the clipped mean square of fourth differences (correlated over four lags, sum of
  // squared autocorrelations 2.6) scatters by about sqrt(2 x 2.6 / 3000) = 4 % in variance, 2 %
  // in sd; 10 % is over four times that.
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::vector<double> v;
  for (int k = 0; k < 3000; ++k) {
    const double t = 10.0 * k;
    const double truth = 20.0 + std::clamp((t - 5000.0) / 60.0, 0.0, 20.0);
    v.push_back(std::round((truth + noise(rng)) / 0.001) * 0.001);
  }
  EXPECT_NEAR(WhiteNoiseSd(v), std::sqrt(4e-6 + 1e-6 / 12.0), 0.1 * 0.002);
}

TEST(WhiteNoiseSd, ACoarselySampledStepResponseIsNotNoise) {
  // A housing (time constant 316 s) following ambient steps of 15 °C every 2250 s, read every
  // 60 s with 2 mK of noise in 1 mK steps (the reference generator's steps25-40 run at 60 s):
  // between samples the response bends by up to 15 °C x (60 / 316)² = 0.5 °C, which second
  // differences took for 98 mK of noise (49x; their 98 % cut). Over 60 seeds of this signal
  // (numpy) the estimate reads 1.024 +- 0.052 of the noise; 15 % is 2.4 sd above that mean and
  // 3.3 below it (an exponential's tail still bends a little at 60 s, a small bias up).
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.002);
  std::vector<double> v;
  const double tau = 316.0, dt = 60.0;
  double T = 25.0;
  for (int k = 0; k < 600; ++k) {
    const double ambient = (static_cast<int>(k * dt / 2250.0) % 2 == 0) ? 25.0 : 40.0;
    T = ambient + (T - ambient) * std::exp(-dt / tau);
    v.push_back(std::round((T + noise(rng)) / 0.001) * 0.001);
  }
  EXPECT_NEAR(WhiteNoiseSd(v), std::sqrt(4e-6 + 1e-6 / 12.0), 0.15 * 0.002);
}

TEST(WhiteNoiseSd, AnExactRampHasNone) {
  std::vector<double> v;
  for (int k = 0; k < 100; ++k) v.push_back(0.25 * k);  // exact in binary
  EXPECT_EQ(WhiteNoiseSd(v), 0.0);
}

TEST(Correlation, IsOneForALineAndNaNForAConstant) {
  EXPECT_DOUBLE_EQ(Correlation({1, 2, 3, 4}, {3, 5, 7, 9}), 1.0);
  EXPECT_DOUBLE_EQ(Correlation({1, 2, 3, 4}, {9, 7, 5, 3}), -1.0);
  EXPECT_TRUE(std::isnan(Correlation({1, 2, 3, 4}, {2, 2, 2, 2})));
  EXPECT_TRUE(std::isnan(Correlation({1, 2}, {1, 2})));
}

/// A channel of 900 fit blocks (10 s), 10 to a score block, residual = white noise of sd
/// `fit_noise` per fit block plus `signal(t)`; covariate "signal" is signal(t) itself.
ChannelResidual Channel(double fit_noise, const std::function<double(double)>& signal, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, fit_noise);
  ChannelResidual c;
  c.run = "r1";
  c.channel = "T3";
  c.fit_blocks_per_score = 10;
  c.score_block_noise = fit_noise / std::sqrt(10.0);
  for (int k = 0; k < 900; ++k) {
    const double t = 10.0 * k + 5.0;
    c.t_s.push_back(t);
    c.residual.push_back(noise(rng) + signal(t));
    c.covariates["signal"].push_back(signal(t));
  }
  return c;
}

TEST(FindUnexplained, PureNoiseIsNeverReported) {
  // 50 channels of pure noise: RMS over noise of 90 score-block means is sqrt(chi²_90 / 90),
  // above 1.5 with probability ~1e-9, and Ljung-Box p below 1e-3 one time in a thousand.
  std::vector<ChannelResidual> all;
  for (uint64_t seed = 1; seed <= 50; ++seed) all.push_back(Channel(0.002, [](double) { return 0.0; }, seed));
  EXPECT_TRUE(FindUnexplained(all, UnexplainedOptions{}).empty());
}

TEST(FindUnexplained, ASlowSignalThreeTimesTheNoiseIsReportedWithWhereAndWhatItMovesWith) {
  // A bump of 3 score-block noise sd between t = 3000 and 5000 s: the RMS over the run is
  // sqrt(1 + 9 x 2000 / 9000) = 1.73 > 1.5; the stretch found is the bump's 20 blocks, give or
  // take a block or two of noise at its edges. Per fit block the bump is 3 x 0.63 = 1.9 mK on
  // 2 mK of noise, present 2/9 of the time: its variance 1.9² (2/9)(7/9) = 0.62 mK², so the
  // residual's correlation with it is sqrt(0.62 / 4.62) = 0.37, known to 1/sqrt(900) = 0.03.
  const double s = 0.002 / std::sqrt(10.0);
  const auto bump = [s](double t) { return t >= 3000.0 && t < 5000.0 ? 3.0 * s : 0.0; };
  const auto found = FindUnexplained({Channel(0.002, bump, 7)}, UnexplainedOptions{});
  ASSERT_EQ(found.size(), 1u);
  const Unexplained& u = found.front();
  EXPECT_EQ(u.channel, "T3");
  EXPECT_EQ(u.run, "r1");
  EXPECT_GT(u.rms_over_noise, 1.5);
  EXPECT_LT(u.ljung_box_p, 1e-3);
  EXPECT_NEAR(u.t_s.first, 3005.0, 300.0);   // within a few score blocks of the bump's edges
  EXPECT_NEAR(u.t_s.second, 4995.0, 300.0);
  EXPECT_NEAR(u.correlates_with.at("signal"), 0.37, 0.12);
  EXPECT_NE(UnexplainedText(u).find("T3 in run r1"), std::string::npos);
}

TEST(FindUnexplained, ANoiseFreeChannelIsLeftOut) {
  ChannelResidual c = Channel(0.002, [](double) { return 1.0; }, 1);
  c.score_block_noise = 0.0;  // nothing to compare with
  EXPECT_TRUE(FindUnexplained({c}, UnexplainedOptions{}).empty());
}

TEST(UnexplainedOptions, RefusesThresholdsThatCannotMeanWhatTheySay) {
  UnexplainedOptions o;
  EXPECT_TRUE(o.IsValid(nullptr));
  o.min_rms_over_noise = 0.9;
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("min_rms_over_noise"), std::string::npos);
  o = UnexplainedOptions{};
  o.max_ljung_box_p = 0.0;
  EXPECT_FALSE(o.IsValid(&why));
}

}  // namespace
}  // namespace rlg::diagnosis
