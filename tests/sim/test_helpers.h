#pragma once
// Helpers shared by the simulator tests.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <string>

#include "sim/gyro.h"
#include "sim/scenario.h"

namespace rlg::test {

inline std::string SourcePath(const std::string& rel) { return std::string(RLG_SOURCE_DIR) + "/" + rel; }

/// Default gyro with every noise source switched off, so physics can be compared exactly.
inline sim::GyroConfig NoiselessDefaultGyro() {
  sim::GyroConfig g = sim::LoadGyro(SourcePath("scenarios/gyros/default.toml"));
  g.noise = sim::GyroNoiseParams{};
  for (auto& s : g.sensors) s.noise = sim::SensorNoiseParams{};
  return g;
}

/// EXPECT that two Eigen objects agree within tol (max abs), printing both and the difference.
#define EXPECT_EIGEN_NEAR(a, b, tol)                                                                   \
  do {                                                                                                 \
    const Eigen::MatrixXd a_ = (a), b_ = (b);                                                          \
    ASSERT_EQ(a_.rows(), b_.rows());                                                                   \
    ASSERT_EQ(a_.cols(), b_.cols());                                                                   \
    EXPECT_LE((a_ - b_).cwiseAbs().maxCoeff(), (tol)) << "a:\n" << a_ << "\nb:\n" << b_ << "\ndiff:\n" \
                                                      << (a_ - b_);                                    \
  } while (0)

}  // namespace rlg::test
