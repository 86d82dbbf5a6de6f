// The sample period and the averaging times of the bias stability.

#include <gtest/gtest.h>

#include <cmath>

#include "model/allan.h"
#include "sim/errors.h"
#include "sim/stats.h"

namespace rlg::model {
namespace {

bool Has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(SamplePeriod, IsTheMedianStepSoAGapDoesNotShiftIt) {
  // Steps 10 10 10 70 10 10: the mean step over the record is 20 s, the sampling is 10 s.
  EXPECT_DOUBLE_EQ(SamplePeriod({0, 10, 20, 30, 100, 110, 120}), 10.0);
  EXPECT_DOUBLE_EQ(SamplePeriod({0, 1, 3}), 1.5);  // even count: mean of the middle two
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

}  // namespace
}  // namespace rlg::model
