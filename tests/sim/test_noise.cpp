// Noise: Allan-deviation round trips and reproducibility.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "model/allan.h"
#include "sim/noise.h"

namespace rlg::sim {
namespace {

std::vector<double> NoiseOnly(const GyroNoiseParams& p, double hours, uint64_t seed) {
  GyroNoise noise(p, 1.0, seed, 0);
  std::vector<double> y(static_cast<size_t>(hours * 3600));
  for (auto& v : y) v = noise.Sample(0.0);
  return y;
}

TEST(GyroNoise, FlickerApproximationHasAFlatAllanFloorAtTheIeeeLevel) {
  GyroNoiseParams p;
  p.bias_instability_dph = 0.0035;
  for (double tau = 30.0; tau <= 3e4; tau *= 2.0) {
    const double adev = std::sqrt(GyroNoise::InstabilityAllanVariance(p, tau));
    // Sum of half-decade Gauss-Markov terms: ripple about the flat 1/f floor stays < 10 %.
    EXPECT_NEAR(adev / (0.664 * p.bias_instability_dph), 1.0, 0.10) << "tau " << tau;
  }
}

TEST(GyroNoise, AllanReadOffsRecoverArwAndBiasInstability) {
  GyroNoiseParams p;
  p.arw_deg_per_sqrt_h = 0.001;
  p.bias_instability_dph = 0.0035;
  const auto y = NoiseOnly(p, 300.0, 7);
  const model::NoiseTerms t = model::FitNoiseTerms(model::OverlappingAllan(y, 1.0));
  // ARW is pinned by ~1e6 overlapping 1 s differences: estimate error < 1 %; 3 % allows for
  // the fit sharing the short-tau points with the other terms.
  EXPECT_NEAR(model::ArwDegPerSqrtHour(t), 0.001, 0.03 * 0.001);
  // The floor is read where 300 h holds only ~100-1000 clusters of 1e3-1e4 s: each Allan
  // point is uncertain by ~5-15 %, the fit averages a few of them: 20 %.
  EXPECT_NEAR(t.bias_instability, 0.0035, 0.20 * 0.0035);
}

// White noise and an instability term updated every sample: the process must be the sum of
// white noise of sigma_w and a Gauss-Markov term of sigma_x and phi = exp(-dt / T), whose
// autocovariance is sigma_w² + sigma_x² at lag 0 and sigma_x² phi^h at lag h >= 1, and it must
// start stationary. (However the two are drawn: as two sequences or, with one draw per sample,
// as the ARMA(1,1) process their sum is.)
TEST(GyroNoise, WhiteNoiseAndAFastTermHaveTheSumsAutocovariance) {
  GyroNoiseParams p;
  p.arw_deg_per_sqrt_h = 1.0 / 60.0;  // sigma_w = 1 °/h at dt = 1 s
  p.bias_instability_dph = 1.0;       // sigma_x = 1 °/h
  p.instability_model = GyroNoiseParams::InstabilityModel::kGaussMarkov;
  p.gauss_markov_time_s = 5.0;  // updated every sample (T / (10 dt) < 3)
  const double phi = std::exp(-1.0 / 5.0);
  const auto y = NoiseOnly(p, 2e6 / 3600.0, 21);
  const double mean = std::accumulate(y.begin(), y.end(), 0.0) / static_cast<double>(y.size());
  for (size_t h = 0; h <= 6; ++h) {
    double c = 0.0;
    for (size_t k = 0; k + h < y.size(); ++k) c += (y[k] - mean) * (y[k + h] - mean);
    c /= static_cast<double>(y.size() - h);
    const double expected = (h == 0 ? 2.0 : std::pow(phi, static_cast<double>(h)));
    // Standard error ~ sqrt(sum of gamma²) / sqrt(N) ~ 2e-3 for these 2e6 samples: 0.012 is 6 of them.
    EXPECT_NEAR(c, expected, 0.012) << "lag " << h;
  }
  // The first sample of 20,000 seeds: variance sigma_w² + sigma_x² = 2 (standard error 0.02).
  double sum2 = 0.0;
  const int seeds = 20000;
  for (int seed = 0; seed < seeds; ++seed) {
    GyroNoise noise(p, 1.0, static_cast<uint64_t>(seed), 0);
    const double v = noise.Sample(0.0);
    sum2 += v * v;
  }
  EXPECT_NEAR(sum2 / seeds, 2.0, 0.1);
}

// The flicker's terms with the white noise, at 1 s (its 10 s term updated every sample, the
// rest held between updates every 3, 9, ... samples) and at 60 s (five terms updated every
// sample): half the mean squared difference of
// successive samples is sigma_w² + sum_j sigma_j² (1 - phi_j) / every_j, phi_j = exp(-every_j
// dt / T_j), every_j the term's update interval in samples (GyroNoise's constructor: the
// largest power of 3 up to T_j / (10 dt), and no less than the previous term's).
TEST(GyroNoise, FlickerWithWhiteNoiseHasItsAllanVarianceAtOneSample) {
  GyroNoiseParams p;
  p.arw_deg_per_sqrt_h = 0.001;
  p.bias_instability_dph = 0.0035;
  for (const double dt : {1.0, 60.0}) {
    double expected = std::pow(60.0 * p.arw_deg_per_sqrt_h, 2) / dt;
    int64_t previous = 1;
    for (const auto& [T, sigma] : GyroNoise::InstabilityTerms(p)) {
      int64_t every = 1;
      while (every * 3 <= static_cast<int64_t>(T / (10.0 * dt))) every *= 3;
      every = std::max(every, previous);
      previous = every;
      expected += sigma * sigma * (1.0 - std::exp(-static_cast<double>(every) * dt / T)) / static_cast<double>(every);
    }
    double sum = 0.0;
    int64_t count = 0;
    for (uint64_t seed = 0; seed < 500; ++seed) {
      GyroNoise noise(p, dt, seed, 0);
      double last = noise.Sample(0.0);
      for (int k = 0; k < 2000; ++k) {
        const double y = noise.Sample(0.0);
        sum += 0.5 * (y - last) * (y - last);
        last = y;
        ++count;
      }
    }
    // ~1e6 differences: a relative standard error of ~0.2 %; 1.5 % is several of them, and a
    // term lost or counted twice moves it by 5-10 % at 60 s.
    EXPECT_NEAR(sum / static_cast<double>(count) / expected, 1.0, 0.015) << "dt " << dt;
  }
}

TEST(GyroNoise, AllanReadOffsRecoverRateRandomWalk) {
  GyroNoiseParams p;
  p.arw_deg_per_sqrt_h = 0.001;
  p.rrw_deg_per_h_per_sqrt_h = 0.02;
  const auto y = NoiseOnly(p, 300.0, 11);
  const model::NoiseTerms t = model::FitNoiseTerms(model::OverlappingAllan(y, 1.0));
  EXPECT_NEAR(model::ArwDegPerSqrtHour(t), 0.001, 0.03 * 0.001);
  // RRW shows only at long tau (> 1e4 s) where few clusters exist: 30 %.
  EXPECT_NEAR(model::RrwDegPerHourPerSqrtHour(t), 0.02, 0.30 * 0.02);
}

TEST(GyroNoise, QuantizationKeepsTheMeanAndEmitsWholePulses) {
  GyroNoiseParams p;
  p.quantization_arcsec = 0.5;
  GyroNoise noise(p, 1.0, 3, 0);
  double sum = 0.0;
  const int n = 10000;
  for (int k = 0; k < n; ++k) {
    const double y = noise.Sample(0.37);
    const double pulses = y * 1.0 / 0.5;
    EXPECT_NEAR(pulses, std::round(pulses), 1e-9);
    sum += y;
  }
  // Integrated angle is exact up to one pulse: mean error <= Q / (n dt).
  EXPECT_NEAR(sum / n, 0.37, 0.5 / n + 1e-12);
}

TEST(SensorNoise, RoundsHalfAwayFromZeroInBlocksAsOneAtATime) {
  // The rounding loop is branch-free (vectorised); it must equal the definition: T + sigma n,
  // then trunc(v / resolution + sign(v) / 2) resolution, for values on both sides of zero and
  // on exact halves (which round away from zero).
  const SensorNoise sensor(SensorNoiseParams{0.0, 0.01});
  std::vector<double> t = {-0.025, -0.015, -0.005, -0.004, 0.004, 0.005, 0.015, 0.025, 12.345, -12.345, 1e300, -1e300};
  std::vector<double> want;
  for (double v : t) {
    const double scaled = v * 100.0 + std::copysign(0.5, v);
    want.push_back(std::abs(scaled) < 0x1p52 ? std::trunc(scaled) * 0.01 : v);
  }
  Rng rng(1, 0);
  sensor.ReadInPlace(t.data(), t.size(), rng);
  EXPECT_EQ(t, want);
  // A reading that rounds to zero from below is +0, not -0, whichever loop ran (the baseline's
  // emulated truncation gives +0; the AVX2 loop's instruction gives -0 and adds 0): the same
  // bytes on every machine ("-0" would print in the CSV).
  EXPECT_EQ(t[3], 0.0);
  EXPECT_FALSE(std::signbit(t[3])) << "-0.004 read as -0";
}

TEST(GyroNoise, SameSeedSameSamplesOtherSeedOthers) {
  GyroNoiseParams p;
  p.arw_deg_per_sqrt_h = 0.001;
  p.bias_instability_dph = 0.0035;
  EXPECT_EQ(NoiseOnly(p, 0.1, 5), NoiseOnly(p, 0.1, 5));
  EXPECT_NE(NoiseOnly(p, 0.1, 5), NoiseOnly(p, 0.1, 6));
}

TEST(Rng, DrawsAreStandardNormalIncludingTheTail) {
  // 4e6 draws: 15,625 blocks, so every path of the block ziggurat runs many times (the top
  // layer and the wedges ~2 % of draws, the tail beyond X[1] = 3.44 ~6e-4).
  Rng rng(2024, 3, 1);
  const size_t n = 4'000'000;
  std::vector<double> z(n);
  rng.Fill(z.data(), n);
  double sum = 0.0, sum2 = 0.0, sum4 = 0.0;
  size_t beyond_1 = 0, beyond_3 = 0, beyond_tail = 0, negative = 0;
  for (double v : z) {
    sum += v;
    sum2 += v * v;
    sum4 += v * v * v * v;
    beyond_1 += std::abs(v) > 1.0;
    beyond_3 += std::abs(v) > 3.0;
    beyond_tail += std::abs(v) > 3.4426198558966521;
    negative += v < 0.0;
  }
  const double N = static_cast<double>(n);
  // Standard errors at n = 4e6: mean 5e-4, variance 7e-4, kurtosis (E z^4 = 3) 4.9e-3; a
  // count with probability p: sqrt(n p (1 - p)). Every bound below is 5 standard errors.
  EXPECT_NEAR(sum / N, 0.0, 5 * 5e-4);
  EXPECT_NEAR(sum2 / N, 1.0, 5 * 7.1e-4);
  EXPECT_NEAR(sum4 / N, 3.0, 5 * 4.9e-3);
  auto expect_count = [&](size_t count, double p, const char* what) {
    EXPECT_NEAR(static_cast<double>(count), N * p, 5 * std::sqrt(N * p * (1 - p))) << what;
  };
  expect_count(negative, 0.5, "z < 0");
  expect_count(beyond_1, std::erfc(1.0 / std::sqrt(2.0)), "|z| > 1");
  expect_count(beyond_3, std::erfc(3.0 / std::sqrt(2.0)), "|z| > 3");
  expect_count(beyond_tail, std::erfc(3.4426198558966521 / std::sqrt(2.0)), "|z| > X[1] (the tail path)");
  // Kolmogorov-Smirnov against Phi on the first 1e5 (sorted): the 0.1 % critical value of
  // sqrt(n) D is 1.95.
  std::vector<double> head(z.begin(), z.begin() + 100'000);
  std::sort(head.begin(), head.end());
  double d = 0.0;
  for (size_t i = 0; i < head.size(); ++i) {
    const double phi = 0.5 * std::erfc(-head[i] / std::sqrt(2.0));
    d = std::max({d, std::abs(phi - static_cast<double>(i) / head.size()), std::abs(static_cast<double>(i + 1) / head.size() - phi)});
  }
  EXPECT_LT(std::sqrt(static_cast<double>(head.size())) * d, 1.95);
}

TEST(Rng, OneAtATimeAndInBlocksGiveTheSameSequence) {
  Rng one(7, 1, 2), blocks(7, 1, 2);
  std::vector<double> a(1000), b(1000);
  for (double& v : a) v = one.Normal();
  // Uneven pieces: part of a block, whole blocks straight into the buffer, then the rest.
  size_t at = 0;
  for (size_t piece : {3u, 300u, 512u, 185u}) {
    blocks.Fill(b.data() + at, piece);
    at += piece;
  }
  EXPECT_EQ(a, b);
  // Another substream is another sequence.
  Rng other(7, 1, 3);
  EXPECT_NE(a.front(), other.Normal());
}

TEST(GyroNoise, BlocksAndSingleSamplesGiveTheSameOutput) {
  // Every term on: white, flicker, random walk, turn-on, quantization.
  GyroNoiseParams p;
  p.arw_deg_per_sqrt_h = 0.001;
  p.bias_instability_dph = 0.0035;
  p.rrw_deg_per_h_per_sqrt_h = 0.02;
  p.quantization_arcsec = 0.001;
  p.turn_on_sigma_dph = 0.001;
  // dt = 1 s: the fastest flicker term updates every sample, the next every 3, 9, ...; 30 s: the
  // first four every sample; 1000 s: the first seven (a chunk's draws are counted ahead).
  for (const double dt : {1.0, 30.0, 1000.0}) {
    GyroNoise single(p, dt, 9, 4), blocked(p, dt, 9, 4);
    std::vector<double> a(2000), b(2000);
    for (size_t k = 0; k < a.size(); ++k) a[k] = single.Sample(0.1 * std::sin(k * 1e-3));
    for (size_t k = 0; k < b.size(); ++k) b[k] = 0.1 * std::sin(k * 1e-3);
    blocked.Apply(b.data(), 7);
    blocked.Apply(b.data() + 7, 1500);
    blocked.Apply(b.data() + 1507, b.size() - 1507);
    EXPECT_EQ(a, b) << "dt " << dt;
  }
}

TEST(SensorNoise, ReadingIsQuantizedToTheResolution) {
  Rng rng(1, 0);
  const SensorNoise sensor(SensorNoiseParams{0.003, 0.01});
  for (double t : {-30.004, 0.0, 12.3456}) {
    const double r = sensor.Read(t, rng);
    EXPECT_NEAR(r / 0.01, std::round(r / 0.01), 1e-6);
    EXPECT_NEAR(r, t, 0.005 + 6 * 0.003);  // half a step plus 6 sigma
  }
}

}  // namespace
}  // namespace rlg::sim
