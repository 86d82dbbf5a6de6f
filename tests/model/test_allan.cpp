// Allan read-offs: which terms the measured curve resolves (closed-form curves and simulated
// records), the bound given for the others, and the sample period and averaging times of the
// bias stability.

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "model/allan.h"
#include "sim/errors.h"
#include "sim/noise.h"
#include "sim/stats.h"

namespace rlg::model {
namespace {

/// An Allan curve exactly on sigma²(tau) = terms, at the octaves an n-sample record at 1 s has
/// (n_samples as OverlappingAllan counts them, for the weights and the error bars).
AllanCurve ClosedFormCurve(const NoiseTerms& terms, size_t n) {
  AllanCurve c;
  for (size_t m = 1; 9 * m <= n; m *= 2) {
    const double tau = static_cast<double>(m);
    c.tau_s.push_back(tau);
    c.adev.push_back(std::sqrt(AllanVariance(terms, tau)));
    c.n_samples.push_back(static_cast<double>(n + 1 - 2 * m));
  }
  return c;
}

std::vector<double> NoiseRecord(const sim::GyroNoiseParams& p, double hours, uint64_t seed) {
  sim::GyroNoise noise(p, 1.0, seed, 0);
  std::vector<double> y(static_cast<size_t>(hours * 3600.0));
  for (auto& v : y) v = noise.Sample(0.0);
  return y;
}

bool Has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// Units below: rate in °/h, time in s, as the reports feed the fit (N = 0.06 °/h sqrt(s) is
// 0.001 °/sqrt(h), the default gyro's ARW).

TEST(AllanReadOffs, WhiteNoiseCurveResolvesArwAloneAndBoundsTheOthers) {
  NoiseTerms truth;
  truth.arw = 0.06;
  const AllanCurve c = ClosedFormCurve(truth, 1 << 17);
  const NoiseReadOffs r = ReadNoiseTerms(c);
  ASSERT_TRUE(r[NoiseTerm::kArw].resolved);
  // An exact curve is fitted exactly: the only error is round-off in the 4-column QR.
  EXPECT_NEAR(r[NoiseTerm::kArw].value, 0.06, 1e-9 * 0.06);
  EXPECT_FALSE(r[NoiseTerm::kBiasInstability].resolved);
  EXPECT_FALSE(r[NoiseTerm::kRrw].resolved);
  EXPECT_TRUE(Has(r[NoiseTerm::kBiasInstability].reason, "too short to reach its flat part"))
      << r[NoiseTerm::kBiasInstability].reason;
  EXPECT_TRUE(Has(r[NoiseTerm::kRrw].reason, "ARW still leads at the longest tau")) << r[NoiseTerm::kRrw].reason;
  // The bound is what the longest tau allows at most: N/sqrt(tau_max) sqrt(1 + 2 rel) / 0.664.
  const size_t last = c.tau_s.size() - 1;
  const double at_last = 0.06 / std::sqrt(c.tau_s[last]) * std::sqrt(1.0 + 2.0 * AllanVarianceRelativeError(c, last)) / 0.664;
  EXPECT_GT(r[NoiseTerm::kBiasInstability].upper_bound, 0.0);
  EXPECT_LE(r[NoiseTerm::kBiasInstability].upper_bound, at_last * (1.0 + 1e-12));
}

TEST(AllanReadOffs, WhitePlusRateRandomWalkCurveResolvesBothButNotTheFlatPart) {
  NoiseTerms truth;
  truth.arw = 0.06;
  truth.rrw = 3.3e-4;  // 0.02 °/h/sqrt(h): crosses the ARW line at tau = sqrt(3) N / K ~ 315 s
  const NoiseReadOffs r = ReadNoiseTerms(ClosedFormCurve(truth, 86400));
  ASSERT_TRUE(r[NoiseTerm::kArw].resolved);
  ASSERT_TRUE(r[NoiseTerm::kRrw].resolved);
  EXPECT_NEAR(r[NoiseTerm::kArw].value, truth.arw, 1e-9 * truth.arw);  // exact curve: round-off
  EXPECT_NEAR(r[NoiseTerm::kRrw].value, truth.rrw, 1e-9 * truth.rrw);
  EXPECT_FALSE(r[NoiseTerm::kBiasInstability].resolved);
  EXPECT_TRUE(Has(r[NoiseTerm::kBiasInstability].reason, "stays below ARW and RRW"))
      << r[NoiseTerm::kBiasInstability].reason;
}

TEST(AllanReadOffs, CurveWithAWideFlatPartResolvesArwBiasInstabilityAndRrw) {
  NoiseTerms truth;
  truth.arw = 0.06;
  truth.bias_instability = 0.0035;  // floor 0.0023 °/h from ~700 s ...
  truth.rrw = 2e-5;                 // ... until K sqrt(tau/3) passes it near 4e4 s
  const NoiseReadOffs r = ReadNoiseTerms(ClosedFormCurve(truth, size_t{1} << 22));
  for (NoiseTerm t : {NoiseTerm::kArw, NoiseTerm::kBiasInstability, NoiseTerm::kRrw}) {
    EXPECT_TRUE(r[t].resolved) << NoiseTermName(t) << ": " << r[t].reason;
  }
  EXPECT_NEAR(r[NoiseTerm::kBiasInstability].value, 0.0035, 1e-9 * 0.0035);  // exact curve: round-off
  EXPECT_FALSE(r[NoiseTerm::kQuantization].resolved);
}

TEST(AllanReadOffs, FlatPartLeadingOnlyAtTheFewClusterEndIsNotResolved) {
  NoiseTerms truth;
  truth.arw = 0.06;
  truth.bias_instability = 0.0048;  // (0.664 B)² = 1.0e-5 passes N²/tau = 7e-6 at tau = 512 s only
  const AllanCurve c = ClosedFormCurve(truth, 7200);
  const NoiseReadOffs r = ReadNoiseTerms(c);
  EXPECT_TRUE(r[NoiseTerm::kArw].resolved);
  EXPECT_FALSE(r[NoiseTerm::kBiasInstability].resolved);
  EXPECT_TRUE(Has(r[NoiseTerm::kBiasInstability].reason, "leads only at tau = 512 s")) << r[NoiseTerm::kBiasInstability].reason;
  EXPECT_TRUE(Has(r[NoiseTerm::kBiasInstability].reason, "14 clusters")) << r[NoiseTerm::kBiasInstability].reason;
  // The measured curve cannot be lower than the truth: the bound holds it.
  EXPECT_GE(r[NoiseTerm::kBiasInstability].upper_bound, 0.0048);
}

TEST(AllanCurve, OctavesSideBySideGiveTheBytesOfOneLoopPerOctave) {
  // OverlappingAllan sums the octaves in one pass, in blocks of differences; each octave's sum
  // adds the same terms in the same order as the textbook loop below, so the curve is equal, not
  // close. Lengths around the blocks' (128 differences) and where octaves end inside a block.
  for (const size_t n : {9u, 10u, 64u, 128u, 129u, 130u, 257u, 1000u, 7201u}) {
    std::vector<double> y(n);
    for (size_t i = 0; i < n; ++i) y[i] = std::cos(1.3 * static_cast<double>(i)) + 2e-4 * static_cast<double>(i * i % 97);
    const double dt = 0.1;
    std::vector<double> theta(n + 1, 0.0);
    for (size_t i = 0; i < n; ++i) theta[i + 1] = theta[i] + y[i] * dt;
    std::vector<double> adev;
    for (size_t m = 1; 3 * m <= n; m *= 2) {
      const size_t terms = n + 1 - 2 * m;
      double sum = 0.0;
      for (size_t k = 0; k < terms; ++k) {
        const double d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
        sum += d * d;
      }
      const double tau = static_cast<double>(m) * dt;
      adev.push_back(std::sqrt(sum / (2.0 * tau * tau * static_cast<double>(terms))));
    }
    EXPECT_EQ(OverlappingAllan(y, dt, 3).adev, adev) << n << " samples";
  }
}

TEST(AllanCurve, FewerClustersThenCutIsTheCurveOfMoreClusters) {
  // The prefix of a 3-cluster curve is the 9-cluster curve, value for value (the same sums);
  // lengths around the powers of two, where the two stop at different octaves.
  for (const size_t n : {9u, 17u, 18u, 35u, 36u, 1000u, 7201u}) {
    std::vector<double> y(n);
    for (size_t i = 0; i < n; ++i) y[i] = std::sin(0.37 * static_cast<double>(i)) + 1e-3 * static_cast<double>(i);
    for (const int k : {3, 9}) {
      const AllanCurve direct = OverlappingAllan(y, 0.5, k);
      const AllanCurve cut = WithMinClusters(OverlappingAllan(y, 0.5, 3), n, k);
      EXPECT_EQ(cut.tau_s, direct.tau_s) << n << " samples, " << k;
      EXPECT_EQ(cut.adev, direct.adev) << n << " samples, " << k;
      EXPECT_EQ(cut.n_samples, direct.n_samples) << n << " samples, " << k;
    }
  }
}

TEST(AllanReadOffs, ConstantRecordResolvesNothingAndWritesNoNan) {
  const AllanCurve c = OverlappingAllan(std::vector<double>(1000, 0.25), 1.0);
  const NoiseReadOffs r = ReadNoiseTerms(c);
  for (const auto& t : r.terms) {
    EXPECT_FALSE(t.resolved);
    EXPECT_TRUE(Has(t.reason, "constant")) << t.reason;
    EXPECT_EQ(t.upper_bound, 0.0);
  }
  nlohmann::json j;
  AddNoiseTermsJson(r, j);
  EXPECT_TRUE(j["arw_deg_per_sqrt_h"].is_null());
  EXPECT_EQ(j["not_resolved"]["arw_deg_per_sqrt_h"]["upper_bound"], 0.0);
}

TEST(AllanReadOffs, TooShortARecordHasNoCurveAndSaysSo) {
  const NoiseReadOffs r = ReadNoiseTerms(OverlappingAllan(std::vector<double>(5, 1.0), 1.0));
  EXPECT_FALSE(r[NoiseTerm::kArw].resolved);
  EXPECT_TRUE(Has(r[NoiseTerm::kArw].reason, "too short")) << r[NoiseTerm::kArw].reason;
}

TEST(AllanReadOffs, SimulatedWhiteNoiseResolvesArwNotBiasInstabilityOrRrw) {
  sim::GyroNoiseParams p;
  p.arw_deg_per_sqrt_h = 0.001;
  const NoiseReadOffs r = ReadNoiseTerms(OverlappingAllan(NoiseRecord(p, 24.0, 3), 1.0));
  ASSERT_TRUE(r[NoiseTerm::kArw].resolved);
  // 86400 samples pin sigma(1 s) to ~0.3 %; 3 % leaves room for the joint fit's other terms.
  EXPECT_NEAR(r[NoiseTerm::kArw].value / 60.0, 0.001, 0.03 * 0.001);
  EXPECT_FALSE(r[NoiseTerm::kBiasInstability].resolved) << r[NoiseTerm::kBiasInstability].value;
  EXPECT_FALSE(r[NoiseTerm::kRrw].resolved) << r[NoiseTerm::kRrw].value;
}

TEST(AllanReadOffs, SimulatedWhitePlusRandomWalkResolvesRrw) {
  sim::GyroNoiseParams p;
  p.arw_deg_per_sqrt_h = 0.001;
  p.rrw_deg_per_h_per_sqrt_h = 0.02;  // leads from ~300 s: a day holds 5 octaves of it
  const NoiseReadOffs r = ReadNoiseTerms(OverlappingAllan(NoiseRecord(p, 24.0, 11), 1.0));
  ASSERT_TRUE(r[NoiseTerm::kRrw].resolved) << r[NoiseTerm::kRrw].reason;
  ASSERT_TRUE(r[NoiseTerm::kArw].resolved);
  // K is read where a day holds 10-300 clusters (±10-40 % per point in variance): 40 %.
  EXPECT_NEAR(r[NoiseTerm::kRrw].value * 60.0, 0.02, 0.40 * 0.02);
  EXPECT_FALSE(r[NoiseTerm::kBiasInstability].resolved);
}

TEST(AllanReadOffs, TwoHoursOfNavigationGradeNoiseDoNotResolveBiasInstabilityButBoundIt) {
  sim::GyroNoiseParams p;  // the default gyro's noise, as in the suite's 2 h runs
  p.arw_deg_per_sqrt_h = 0.001;
  p.bias_instability_dph = 0.0035;
  for (uint64_t seed : {1, 2, 3, 4, 5}) {
    const NoiseReadOffs r = ReadNoiseTerms(OverlappingAllan(NoiseRecord(p, 2.0, seed), 1.0));
    EXPECT_FALSE(r[NoiseTerm::kBiasInstability].resolved) << "seed " << seed;
    // The bound allows 2 sigma at each point: the truth lies below it.
    EXPECT_GE(r[NoiseTerm::kBiasInstability].upper_bound, 0.0035) << "seed " << seed;
  }
}

TEST(AllanReadOffs, HundredHoursOfNavigationGradeNoiseResolveBiasInstability) {
  sim::GyroNoiseParams p;
  p.arw_deg_per_sqrt_h = 0.001;
  p.bias_instability_dph = 0.0035;
  const NoiseReadOffs r = ReadNoiseTerms(OverlappingAllan(NoiseRecord(p, 100.0, 7), 1.0));
  ASSERT_TRUE(r[NoiseTerm::kBiasInstability].resolved) << r[NoiseTerm::kBiasInstability].reason;
  // The floor is read on ~30-300 clusters per point (±10-25 % in variance) and the flicker
  // approximation ripples by < 10 % (test_noise): 25 %.
  EXPECT_NEAR(r[NoiseTerm::kBiasInstability].value, 0.0035, 0.25 * 0.0035);
}

TEST(AllanReadOffs, JsonHasNullAndAReasonForEachUnresolvedTerm) {
  NoiseTerms truth;
  truth.arw = 0.06;
  nlohmann::json j;
  AddNoiseTermsJson(ReadNoiseTerms(ClosedFormCurve(truth, 7200)), j);
  EXPECT_NEAR(j["arw_deg_per_sqrt_h"].get<double>(), 0.001, 1e-12);  // 0.06 / 60, round-off
  EXPECT_TRUE(j["bias_instability_dph"].is_null());
  EXPECT_TRUE(j["rrw_deg_per_h_per_sqrt_h"].is_null());
  EXPECT_TRUE(j["not_resolved"]["bias_instability_dph"]["reason"].is_string());
  EXPECT_FALSE(j["not_resolved"].contains("arw_deg_per_sqrt_h"));
}

TEST(SamplePeriod, IsTheMedianStepSoAGapDoesNotShiftIt) {
  // Steps 10 10 10 70 10 10: the mean step over the record is 20 s, the sampling is 10 s.
  EXPECT_DOUBLE_EQ(SamplePeriod({0, 10, 20, 30, 100, 110, 120}), 10.0);
  EXPECT_DOUBLE_EQ(SamplePeriod({0, 1, 3}), 1.5);  // even count: mean of the middle two
  EXPECT_DOUBLE_EQ(SamplePeriod({0, 1, 5}), 2.5);  // only the last step differs: still the median
  EXPECT_EQ(SamplePeriod({0, 0.5, 1.0, 1.5}), 0.5);  // evenly sampled: the step itself, exactly
  // The mean of the two middle steps, as for uneven steps: +0 from -0 and +0; inf from 1e308 twice.
  EXPECT_FALSE(std::signbit(SamplePeriod({0.0, -0.0, 0.0})));
  EXPECT_TRUE(std::isinf(SamplePeriod({-5e307, 5e307, 1.5e308})));
  EXPECT_THROW(SamplePeriod({5.0}), InputError);
}

TEST(BiasStability, IsTheSpreadOfConsecutiveBlockMeans) {
  const std::vector<double> y = {1, 2, 3, 4, 5, 6, 7};
  // tau = 2 s at 1 s: blocks (1,2) (3,4) (5,6) -> 1.5, 3.5, 5.5; 1 sigma (n - 1) = 2.
  const Stability s = BiasStability(y, 1.0, 2.0);
  EXPECT_DOUBLE_EQ(s.sigma, 2.0);
  EXPECT_EQ(s.blocks, 3u);
  EXPECT_DOUBLE_EQ(s.averaging_s, 2.0);
  EXPECT_FALSE(s.adjusted());
  EXPECT_THROW(BiasStability(y, 1.0, 4.0), InputError);  // one block only
}

TEST(BiasStability, BelowTheSamplePeriodIsRefusedWhenAskedForAndOneSampleWhenADefault) {
  const std::vector<double> y = {1, 2, 3, 4, 5, 6, 7};  // as if every 10 s
  try {
    BiasStability(y, 10.0, 1.0, BelowSamplePeriod::kRefuse);
    FAIL() << "1 s on 10 s samples was accepted";
  } catch (const InputError& e) {
    EXPECT_TRUE(Has(e.what(), "1 s is below the 10 s sample period")) << e.what();
  }
  const Stability s = BiasStability(y, 10.0, 1.0, BelowSamplePeriod::kUseOneSample);
  EXPECT_TRUE(s.below_sample_period);
  EXPECT_TRUE(s.adjusted());
  EXPECT_DOUBLE_EQ(s.averaging_s, 10.0);
  EXPECT_NEAR(s.sigma, std::sqrt(28.0 / 6.0), 1e-12);  // the samples themselves; round-off
  EXPECT_TRUE(Has(DescribeAveraging(s, 10.0), "10 s (one sample: 1 s is below the 10 s sample period)"))
      << DescribeAveraging(s, 10.0);
}

TEST(BiasStability, HundredSecondsOnSixtySecondSamplesIsComputedAndNamedAt120) {
  std::vector<double> y;
  for (int k = 0; k < 12; ++k) y.push_back(k % 3 == 0 ? 1.0 : 0.0);  // 1 0 0 1 0 0 ...
  const Stability s = BiasStability(y, 60.0, 100.0, BelowSamplePeriod::kUseOneSample);
  EXPECT_EQ(s.samples_per_block, 2u);
  EXPECT_DOUBLE_EQ(s.averaging_s, 120.0);
  EXPECT_TRUE(s.adjusted());
  // Pair means .5 .5 0 .5 .5 0 ... hand-computed: blocks (1,0)(0,1)(0,0)(1,0)(0,1)(0,0).
  EXPECT_NEAR(s.sigma, sim::StdDev({0.5, 0.5, 0.0, 0.5, 0.5, 0.0}), 1e-15);
  EXPECT_TRUE(Has(DescribeAveraging(s, 60.0), "120 s (2 samples of 60 s")) << DescribeAveraging(s, 60.0);
}

TEST(BiasStability, PairGivesTheBytesOfTwoStabilitiesAndTheirBlockMeans) {
  // BiasStabilityPair and MeanPair add the same terms in the same order as BiasStability,
  // BlockMeans and sim::Mean, only two records side by side: equal, not close.
  std::vector<double> a(7201), b(7201);
  for (size_t i = 0; i < a.size(); ++i) {
    a[i] = 0.8 + 0.1 * std::sin(0.013 * static_cast<double>(i)) + 1e-3 * static_cast<double>(i % 7);
    b[i] = 1e-3 * std::cos(1.7 * static_cast<double>(i));
  }
  const std::array<double, 2> means = MeanPair(a, b);
  EXPECT_EQ(means[0], sim::Mean(a));
  EXPECT_EQ(means[1], sim::Mean(b));
  // Blocks of one sample (1 s; and 0.5 s raised to one sample), of two, of 100, of 3,600.
  for (const double tau : {0.5, 1.0, 2.0, 100.0, 3600.0}) {
    std::array<std::vector<double>, 2> block_means;
    const auto pair = BiasStabilityPair(a, b, 1.0, tau, BelowSamplePeriod::kUseOneSample, &block_means);
    for (size_t k = 0; k < 2; ++k) {
      const std::vector<double>& y = k == 0 ? a : b;
      const Stability one = BiasStability(y, 1.0, tau, BelowSamplePeriod::kUseOneSample);
      EXPECT_EQ(pair[k].sigma, one.sigma) << tau << " s, record " << k;
      EXPECT_EQ(pair[k].samples_per_block, one.samples_per_block);
      EXPECT_EQ(pair[k].blocks, one.blocks);
      EXPECT_EQ(pair[k].averaging_s, one.averaging_s);
      EXPECT_EQ(block_means[k], BlockMeans(y, one.samples_per_block)) << tau << " s, record " << k;
    }
  }
  // The single stability's errors, and none for records that are not a pair.
  EXPECT_THROW(BiasStabilityPair(a, b, 1.0, 4000.0), InputError);  // one block only
  EXPECT_THROW(BiasStabilityPair(a, b, 1.0, 0.5, BelowSamplePeriod::kRefuse), InputError);
  EXPECT_THROW(BiasStabilityPair(a, std::vector<double>(10), 1.0, 1.0), std::invalid_argument);
}

}  // namespace
}  // namespace rlg::model
