// Noise: Allan-deviation round trips and reproducibility.

#include <gtest/gtest.h>

#include <cmath>

#include "model/allan.h"
#include "sim/noise.h"

namespace rlg::sim {
namespace {

std::vector<double> NoiseOnly(const GyroNoiseParams& p, double hours, uint64_t seed) {
  Rng rng(seed, 0);
  GyroNoise noise(p, 1.0, rng);
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
  Rng rng(3, 0);
  GyroNoise noise(p, 1.0, rng);
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

TEST(GyroNoise, SameSeedSameSamplesOtherSeedOthers) {
  GyroNoiseParams p;
  p.arw_deg_per_sqrt_h = 0.001;
  p.bias_instability_dph = 0.0035;
  EXPECT_EQ(NoiseOnly(p, 0.1, 5), NoiseOnly(p, 0.1, 5));
  EXPECT_NE(NoiseOnly(p, 0.1, 5), NoiseOnly(p, 0.1, 6));
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
