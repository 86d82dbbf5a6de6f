#pragma once
// Helpers shared by the simulator tests (and io and diagnosis tests); the function bodies are
// in test_helpers.cpp, compiled once into rlg_test_support (tests/CMakeLists.txt).

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <filesystem>
#include <fstream>
#include <string>

#include "io/gyro_file.h"
#include "sim/bias_model.h"
#include "sim/errors.h"
#include "sim/gyro.h"
#include "sim/scenario.h"
#include "tools/source_dir.h"

namespace rlg::test {

/// A file of the repository (tools/source_dir.h).
using tools::SourcePath;

/// Default gyro with every noise source switched off, so physics can be compared exactly.
sim::GyroConfig NoiselessDefaultGyro();

/// A 4 h run at 10 s whose ambient dwells at 20 °C, ramps to 60 °C, dwells and ramps back: every
/// catalog effect shows in it (rates, gradients, heating and cooling, a 40 °C block excursion).
sim::RunSpec RiseFall();

/// Smooth node temperatures (°C) and their exact rates (°C/s), nodes x samples: each node rises
/// by 40 a_i °C and falls back, with its own amplitude and delay, so that gradients, heating and
/// cooling, rates and a 40 °C block excursion all occur.
struct Track {
  Eigen::MatrixXd T, Tdot;
};
Track SmoothCycle(int nodes);

/// Bias of `params` along a track, sample by sample as the simulator evaluates it.
std::vector<double> BiasAlong(const sim::BiasParams& params, const Track& x);

/// The noiseless default gyro with a mode spacing of 30 °C, the spacing a mode hop's applied
/// parameters give in the bias-term tests: that spacing sets the path-length control's travel
/// term too, and with the nominal at the same spacing a bias difference is the effect's term alone.
sim::GyroConfig NominalForBiasTerms();

/// A fixture with a fresh directory per test (removed after it), files written into it, and the
/// message of an expected InputError.
class TempDir : public ::testing::Test {
 protected:
  void SetUp() override;
  void TearDown() override;
  /// Writes `text` to the file `name` in the test's directory; returns its path.
  std::string Write(const std::string& name, const std::string& text);
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
