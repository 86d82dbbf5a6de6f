// Coverage of the Eq. (2) fits' reported 95 % intervals: simulate many
// datasets from Eq. (2) with known A, fit each, count how often A ± t·SE holds the truth.
//
// Each dataset: nine warm-up runs after a soak at Ti0 = -30 ... +50 °C, 2 h at 10 s samples,
// bias = c_r + Eq. (2) + noise, with c_r a random turn-on bias of the run that the fit must not
// need to know; each dataset draws its own from its own seed. The temperature curves have the
// shape the project's default gyro simulates for paper-fixed (T1 +0.09 °C after 120 s, +1.5 °C
// after 2 h; T2 - T1 a lagged rise to ~1 °C), the rise 1.75 °C at -30 °C and 1.43 °C at +50 °C.
// T1 moves during the B0 window, as in a real warm-up.
//
// The intervals are judged under white noise (0.02 °/h per 10 s sample) and under white noise
// plus the bias instability of docs/physics.md (first-order Gauss-Markov, tau = 3600 s,
// sigma = 0.0035 °/h). Both tests also print each method's bias and spread of the A_kl and the
// compensated bias of a held-out run, the numbers behind the README's advice on which method
// to use.

#include <gtest/gtest.h>

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "model/guo2006.h"
#include "tests/model/guo2006_truth.h"

namespace rlg::model {
namespace {

struct Noise {
  double white_dph = 0.02;  ///< per 10 s sample
  double gm_sigma_dph = 0.0;
  double gm_tau_s = 3600.0;
};

constexpr double kSamplePeriod_s = 10.0;
constexpr double kRunLength_s = 7200.0;

/// The temperatures of a warm-up run after a soak at Ti0, and a bias column for DrawBias.
sim::Run WarmUpRun(const std::string& id, double Ti0) {
  sim::Run r;
  r.id = id;
  auto& Ti = r.AddColumn("T1");
  auto& Tj = r.AddColumn("T2");
  r.AddColumn("bias_dph");
  // Self-heating rises 18 % less at +50 °C than at -30 °C (power drift, radiation): runs differ
  // in how well they show each term, as measured runs do.
  const double rise = 1.55 - 0.004 * (Ti0 - 20.0);
  const double ta = 3000.0, tb = 600.0;  // a second-order lag: the anode follows the block
  for (double t = 0.0; t <= kRunLength_s; t += kSamplePeriod_s) {
    const double ti = Ti0 + rise * (1.0 - std::exp(-t / 2000.0));
    r.t_s.push_back(t);
    Ti.push_back(ti);
    Tj.push_back(ti + 1.2 * (1.0 - (ta * std::exp(-t / ta) - tb * std::exp(-t / tb)) / (ta - tb)));
  }
  r.columns[static_cast<size_t>(r.Find("bias_dph"))].resize(r.size());
  return r;
}

/// Overwrites the run's bias with turn-on bias c + Eq. (2) + noise (in place: the runs are
/// reused, thousands of datasets without reallocating).
void DrawBias(sim::Run& run, double c, const Noise& noise, boost::random::mt19937_64& rng) {
  boost::random::normal_distribution<double> normal;
  const auto& Ti = run.Column("T1");
  const auto& Tj = run.Column("T2");
  auto& b = run.columns[static_cast<size_t>(run.Find("bias_dph"))];
  const double Ti0 = Ti.front();
  const Eigen::Vector3d a = TrueA() * Eigen::Vector3d(1.0, Ti0, Ti0 * Ti0);
  // Exact discretisation of the Gauss-Markov process, started in its stationary distribution.
  const double phi = std::exp(-kSamplePeriod_s / noise.gm_tau_s);
  double gm = noise.gm_sigma_dph * normal(rng);
  for (size_t i = 0; i < run.size(); ++i) {
    b[i] = c + a.dot(Guo2006Features(Ti[i], Tj[i], Ti0)) + noise.white_dph * normal(rng) + gm;
    gm = phi * gm + std::sqrt(1.0 - phi * phi) * noise.gm_sigma_dph * normal(rng);
  }
}

/// What a series of fits tells about one method.
struct Tally {
  int datasets = 0;
  Eigen::Matrix3d covered = Eigen::Matrix3d::Zero();    ///< datasets whose interval holds A_kl
  Eigen::Matrix3d error_sum = Eigen::Matrix3d::Zero();  ///< sum of (A_hat - A)
  Eigen::Matrix3d error_sq = Eigen::Matrix3d::Zero();   ///< sum of (A_hat - A)²
  Eigen::Matrix3d half_width = Eigen::Matrix3d::Zero(); ///< sum of the interval half-widths
  double after_sum = 0.0, after_sq = 0.0;               ///< compensated bias of the held-out run
  double prediction_sq = 0.0;                           ///< mean square of (model_hat - model)

  Eigen::Matrix3d Coverage() const { return covered / datasets; }
  Eigen::Matrix3d Bias() const { return error_sum / datasets; }
  Eigen::Matrix3d Sd() const {
    return (error_sq / datasets - Bias().cwiseProduct(Bias())).cwiseSqrt();
  }
};

/// Fits `datasets` datasets (seeds first_seed, first_seed + 1, ...) with `method` and scores
/// each against the truth; the compensated bias is that of a fresh run at Ti0 = 15 °C (inside
/// the fitted range, between two fitted ambients), compensated as `compensate` does.
Tally Measure(FitOptions::Method method, const Noise& noise, int datasets, uint64_t first_seed) {
  Tally t;
  FitOptions o;
  o.method = method;
  const Eigen::Matrix3d A = TrueA();
  std::vector<sim::Run> runs;
  for (int k = 0; k < 9; ++k) runs.push_back(WarmUpRun("run" + std::to_string(k), -30.0 + 10.0 * k));
  std::vector<const sim::Run*> ptrs;
  for (const auto& r : runs) ptrs.push_back(&r);
  sim::Run held = WarmUpRun("held", 15.0);
  const auto& Ti = held.Column("T1");
  const auto& Tj = held.Column("T2");
  const auto& b = held.Column("bias_dph");
  const Eigen::Vector3d a_held = A * Eigen::Vector3d(1.0, 15.0, 225.0);
  for (int d = 0; d < datasets; ++d) {
    boost::random::mt19937_64 rng(first_seed + static_cast<uint64_t>(d));
    boost::random::normal_distribution<double> normal;
    for (auto& r : runs) DrawBias(r, 0.7 + 0.05 * normal(rng), noise, rng);
    const Guo2006Coefficients c = FitGuo2006(ptrs, o);
    const Eigen::Matrix3d hw = c.ConfidenceHalfWidth(0.95);
    const Eigen::Matrix3d err = c.A - A;
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) t.covered(k, l) += std::abs(err(k, l)) <= hw(k, l) ? 1.0 : 0.0;
    t.error_sum += err;
    t.error_sq += err.cwiseProduct(err);
    t.half_width += hw;

    DrawBias(held, 0.7, noise, rng);
    const double B0 = InitialBias(held, c.b0_window_s);
    double after = 0.0, pred = 0.0;
    for (size_t i = 0; i < held.size(); ++i) {
      const double model = c.Predict(Ti[i], Tj[i], Ti.front());
      after += b[i] - B0 - model;
      pred += std::pow(model - a_held.dot(Guo2006Features(Ti[i], Tj[i], Ti.front())), 2);
    }
    after /= static_cast<double>(held.size());
    t.after_sum += after;
    t.after_sq += after * after;
    t.prediction_sq += pred / static_cast<double>(held.size());
    ++t.datasets;
  }
  return t;
}

void Print(const std::string& title, const Tally& t) {
  const Eigen::Matrix3d cov = t.Coverage(), bias = t.Bias(), sd = t.Sd(), hw = t.half_width / t.datasets;
  std::printf("%s, %d datasets\n  %-4s %9s %12s %12s %12s\n", title.c_str(), t.datasets, "", "coverage", "bias", "sd",
              "mean 95% hw");
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l)
      std::printf("  A%d%d %8.1f%% %+12.3e %12.3e %12.3e\n", k + 1, l, 100.0 * cov(k, l), bias(k, l), sd(k, l),
                  hw(k, l));
  const double mean_after = t.after_sum / t.datasets;
  std::printf("  held-out run at 15 °C: compensated bias mean %+.5f, sd %.5f °/h; model error rms %.5f °/h\n",
              mean_after, std::sqrt(t.after_sq / t.datasets - mean_after * mean_after),
              std::sqrt(t.prediction_sq / t.datasets));
}

// Acceptance band for a nominal 95 % interval. Each coefficient's coverage over N datasets is
// binomial with sd sqrt(0.95 * 0.05 / N) = 0.56 % for N = 1500: 93-97 % is +-3.6 sd, a false
// failure chance of 3e-4 per coefficient and < 0.6 % over the 18 checked (9 coefficients, two
// methods). The nine intervals of one dataset are correlated (the A_k0, A_k1, A_k2 of one k
// come from the same per-run a_k), so the pooled coverage over N x 9 intervals is no better
// known than one coefficient's: it is held to the same band, not to a 9-fold narrower one.
constexpr int kDatasets = 1500;
constexpr double kCoverageLow = 0.93, kCoverageHigh = 0.97;

void ExpectHonest(const Tally& t, const char* method) {
  const Eigen::Matrix3d cov = t.Coverage();
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) {
      EXPECT_GE(cov(k, l), kCoverageLow) << method << " A" << k + 1 << l;
      EXPECT_LE(cov(k, l), kCoverageHigh) << method << " A" << k + 1 << l;
    }
  EXPECT_GE(cov.mean(), kCoverageLow) << method;
  EXPECT_LE(cov.mean(), kCoverageHigh) << method;
}

/// Both methods on the same `datasets` (seeds from first_seed), printed and judged.
void ExpectBothMethodsHonest(const Noise& noise, uint64_t first_seed, const std::string& label) {
  const Tally joint = Measure(FitOptions::Method::kJoint, noise, kDatasets, first_seed);
  const Tally two_stage = Measure(FitOptions::Method::kTwoStage, noise, kDatasets, first_seed);
  Print("joint, " + label, joint);
  Print("two_stage, " + label, two_stage);
  ExpectHonest(joint, "joint");
  ExpectHonest(two_stage, "two_stage");
}

TEST(Guo2006Coverage, NominalNinetyFivePercentIntervalsHoldTheTruthUnderWhiteNoiseForBothMethods) {
  ExpectBothMethodsHonest(Noise{}, 1000, "white noise 0.02 °/h per 10 s");
}

TEST(Guo2006Coverage, NominalNinetyFivePercentIntervalsHoldTheTruthWithBiasInstabilityToo) {
  // Bias instability wanders over the hour a run lasts: the within-run residuals cannot show it
  // (the old white-noise formula covered 23-78 % here), the run-to-run scatter does. The joint
  // fit's error model (runs' errors of white-noise shape with one common covariance) is an
  // approximation under correlated noise; for this design (9 runs of 2 h, tau = 1 h) it
  // measured within the same band, which is what this test holds it to. It is not a claim for
  // every noise and design.
  Noise gm;
  gm.gm_sigma_dph = 0.0035;
  ExpectBothMethodsHonest(gm, 500000, "white 0.02 °/h per 10 s + Gauss-Markov 0.0035 °/h, tau 3600 s");
}

}  // namespace
}  // namespace rlg::model
