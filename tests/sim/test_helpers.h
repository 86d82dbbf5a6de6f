#pragma once
// Helpers shared by the simulator tests.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/gyro_file.h"
#include "sim/errors.h"
#include "sim/gyro.h"
#include "sim/scenario.h"

namespace rlg::test {

inline std::string SourcePath(const std::string& rel) { return std::string(RLG_SOURCE_DIR) + "/" + rel; }

/// Default gyro with every noise source switched off, so physics can be compared exactly.
inline sim::GyroConfig NoiselessDefaultGyro() {
  sim::GyroConfig g = io::LoadGyro(SourcePath("scenarios/gyros/default.toml"));
  g.noise = sim::GyroNoiseParams{};
  for (auto& s : g.sensors) s.noise = sim::SensorNoiseParams{};
  return g;
}

/// A 4 h run at 10 s whose ambient dwells at 20 °C, ramps to 60 °C, dwells and ramps back: every
/// catalog effect shows in it (rates, gradients, heating and cooling, a 40 °C block excursion).
inline sim::RunSpec RiseFall() {
  sim::RunSpec r;
  r.id = "rise-fall";
  r.duration_s = 14400;
  r.sample_period_s = 10;
  r.ambient = sim::Profile::Table({{0, 20}, {1800, 20}, {4200, 60}, {7200, 60}, {9600, 20}});
  return r;
}

/// A fixture with a fresh directory per test (removed after it), files written into it, and the
/// message of an expected InputError.
class TempDir : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("rlg_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->test_suite_name()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Write(const std::string& name, const std::string& text) {
    const auto p = dir_ / name;
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  /// Message of the InputError `f` throws (fails the test if none).
  template <typename F>
  std::string ErrorOf(F f) {
    try {
      f();
    } catch (const InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "expected InputError";
    return "";
  }
  std::filesystem::path dir_;
};

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
