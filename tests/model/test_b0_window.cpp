// B0Window (model/b0_window.h): the running mean of the samples inside the window from a run's
// first sample, frozen by the first sample at or past its end. Exact arithmetic: the samples are
// small integers, whose sums and means below are exact in binary.

#include <gtest/gtest.h>

#include "model/b0_window.h"

namespace rlg::model {
namespace {

TEST(B0Window, IsTheRunningMeanInsideTheWindowThenFrozen) {
  B0Window b0(30.0);
  // Samples every 10 s from t = 100 s: 100, 110, 120 lie inside [100, 130); 130 freezes.
  const double bias[] = {1.0, 2.0, 6.0, 50.0, -7.0};
  const double expected[] = {1.0, 1.5, 3.0, 3.0, 3.0};
  for (int k = 0; k < 5; ++k) {
    const bool inside = b0.Add(100.0 + 10.0 * k, bias[k]);
    EXPECT_EQ(inside, k < 3) << k;
    EXPECT_EQ(b0.value(), expected[k]) << k;
    EXPECT_EQ(b0.frozen(), k >= 3) << k;
  }
  EXPECT_EQ(b0.count(), 3);
  // A sample back inside the window's times after it froze does not reopen it.
  EXPECT_FALSE(b0.Add(105.0, 100.0));
  EXPECT_EQ(b0.value(), 3.0);
}

TEST(B0Window, ResetStartsANewRunAtItsOwnFirstSample) {
  B0Window b0;  // the paper's 120 s
  EXPECT_EQ(b0.window_s(), kB0Window_s);
  b0.Add(0.0, 4.0);
  b0.Add(200.0, 9.0);
  ASSERT_TRUE(b0.frozen());
  b0.Reset();
  EXPECT_FALSE(b0.frozen());
  EXPECT_EQ(b0.count(), 0);
  EXPECT_TRUE(b0.Add(1000.0, 2.0));    // the new run's power-on
  EXPECT_TRUE(b0.Add(1119.0, 4.0));    // 119 s later: inside
  EXPECT_FALSE(b0.Add(1120.0, 80.0));  // 120 s later: the end, excluded
  EXPECT_EQ(b0.value(), 3.0);
}

}  // namespace
}  // namespace rlg::model
