// Coverage of the polynomial fits' reported 95 % intervals (model/linear_fit.h: cluster-robust
// errors over contiguous blocks, Student's t at blocks - 1 dof): many datasets made from a known
// model plus correlated noise, each fitted, counting how often value ± t SE holds the truth.
//
// Each dataset: chamber cycles of 1 h at 2 s samples (tests/model/poly_truth.h: the channel
// swings between about -10 and +60 °C), bias from the cubic of test_poly_model.cpp plus AR(1)
// noise of 0.05 °/h. Each test prints the coverage of every coefficient, and of the white-noise
// formula sigma² (X^T X)^-1 on the same fits for comparison.

#include <gtest/gtest.h>

#include <cstdio>
#include <string>
#include <vector>

#include "model/linear_fit.h"
#include "model/poly_fit.h"
#include "tests/model/poly_truth.h"

namespace rlg::model {
namespace {

struct Coverage {
  int datasets = 0;
  std::vector<double> robust, white;  ///< per coefficient: fraction of intervals holding the truth
  double Mean(const std::vector<double>& v) const {
    double s = 0.0;
    for (double x : v) s += x;
    return s / static_cast<double>(v.size());
  }
};

/// Fits of `o` on `runs`, their bias drawn from `spec` with coefficients `truth` plus `noise`
/// (and, with a power-on offset, a turn-on bias of its own per run); `datasets` fits from seeds
/// first_seed, ...
Coverage Measure(std::vector<sim::Run>& data, const PolySpec& spec, const Eigen::VectorXd& truth, const PolyFitOptions& o,
                 const Ar1& noise, int datasets, uint64_t first_seed) {
  std::vector<const sim::Run*> runs;
  for (const auto& r : data) runs.push_back(&r);
  Coverage c;
  c.robust.assign(static_cast<size_t>(truth.size()), 0.0);
  c.white = c.robust;
  for (int d = 0; d < datasets; ++d) {
    boost::random::mt19937_64 rng(first_seed + static_cast<uint64_t>(d));
    boost::random::normal_distribution<double> normal;
    for (auto& run : data) DrawBias(run, spec, truth, spec.offset == OffsetRule::kFitted ? 0.0 : 12.0 + normal(rng), noise, rng);
    const PolyModel m = FitPoly(runs, o);
    // The white-noise formula on the same fit, for comparison.
    const LinearFit lf = FitLinear(BuildDesign(runs, PolyRegressors(m.spec)), LinearFitOptions{});
    const double t_white = StudentQuantile(0.95, static_cast<double>(lf.n) - static_cast<double>(truth.size()));
    for (Eigen::Index i = 0; i < truth.size(); ++i) {
      const Coefficient& k = m.coefficients[static_cast<size_t>(i)];
      const double err = std::abs(k.value - truth[i]);
      c.robust[static_cast<size_t>(i)] += err <= StudentQuantile(0.95, k.dof) * k.standard_error ? 1.0 : 0.0;
      c.white[static_cast<size_t>(i)] += err <= t_white * lf.white_standard_error[i] ? 1.0 : 0.0;
    }
    ++c.datasets;
  }
  for (auto* v : {&c.robust, &c.white})
    for (double& x : *v) x /= datasets;
  return c;
}

/// `runs` chamber cycles (each from its own phase, each with its own turn-on bias with a
/// power-on offset), the cubic, AR(1) noise; `datasets` fits from seeds first_seed, ...
Coverage Measure(OffsetRule offset, const Ar1& noise, int runs_count, int datasets, uint64_t first_seed) {
  std::vector<sim::Run> cycles;
  for (int r = 0; r < runs_count; ++r) cycles.push_back(CycleRun("cycle" + std::to_string(r), 2.0, 1.0, 0.7 * r));
  std::vector<const sim::Run*> runs;
  for (const auto& r : cycles) runs.push_back(&r);
  const double reference = offset == OffsetRule::kPowerOn ? 35.0 : NAN;
  const PolySpec spec = SpecFor(runs, 3, offset, {}, reference);
  const double all[4] = {30.0, 1.5, -0.02, 3e-4};
  const Eigen::VectorXd truth = offset == OffsetRule::kFitted ? Eigen::Map<const Eigen::VectorXd>(all, 4)
                                                              : Eigen::Map<const Eigen::VectorXd>(all + 1, 3);
  PolyFitOptions o;
  o.offset = offset;
  if (offset == OffsetRule::kPowerOn) o.reference_C = 35.0;
  return Measure(cycles, spec, truth, o, noise, datasets, first_seed);
}

void Print(const std::string& label, const Coverage& c) {
  std::printf("%s, %d datasets: cluster-robust", label.c_str(), c.datasets);
  for (double x : c.robust) std::printf(" %.1f%%", 100.0 * x);
  std::printf(" (mean %.1f%%); white-noise formula", 100.0 * c.Mean(c.robust));
  for (double x : c.white) std::printf(" %.1f%%", 100.0 * x);
  std::printf(" (mean %.1f%%)\n", 100.0 * c.Mean(c.white));
}

// 400 datasets: each coefficient's coverage is binomial with sd sqrt(0.95 * 0.05 / 400) = 1.1 %,
// so 91.5-98.5 % is +-3.2 sd (a false failure chance of 1.4e-3 per coefficient). The coverage
// of a fit's coefficients together is no better known (their intervals are correlated).
constexpr int kDatasets = 400;
constexpr double kLow = 0.915, kHigh = 0.985;

void ExpectWithin(const Coverage& c, const std::string& label, double low) {
  for (size_t i = 0; i < c.robust.size(); ++i) {
    EXPECT_GE(c.robust[i], low) << label << " coefficient " << i;
    EXPECT_LE(c.robust[i], kHigh) << label << " coefficient " << i;
  }
}

TEST(ModelCoverage, NinetyFivePercentIntervalsHoldTheTruthUnderAr1NoiseWithAFittedOffset) {
  // Correlation time 9 samples (18 s): the residuals' lag-1 autocorrelation puts the run in
  // 10 blocks of 180 samples (model/linear_fit.h). Measured: 94.0-95.0 %.
  const Coverage c = Measure(OffsetRule::kFitted, Ar1{0.05, 9.0}, 1, kDatasets, 5000);
  Print("fitted offset, one run, AR(1) tau 9 samples", c);
  ExpectWithin(c, "fitted", kLow);
  // The white-noise formula is far too narrow on these residuals: measured 30-41 %.
  EXPECT_LT(c.Mean(c.white), 0.6);
}

TEST(ModelCoverage, NinetyFivePercentIntervalsHoldTheTruthWithAPowerOnOffsetWhoseB0CarriesTheNoise) {
  // Three power-ons, each with its own turn-on bias; each run's B0 is a 120 s mean of the noise
  // (60 samples of a 60-sample correlation), whose error the coefficients carry. Measured:
  // 93.0-96.8 % (the white-noise formula: 9-13 %).
  const Coverage c = Measure(OffsetRule::kPowerOn, Ar1{0.05, 30.0}, 3, kDatasets, 6000);
  Print("power-on offset, three runs, AR(1) tau 30 samples", c);
  ExpectWithin(c, "power_on", kLow);
}

TEST(ModelCoverage, SlowNoiseNearTheBlocksLengthIsCoveredLessWell) {
  // "Random-walk-ish" noise: a correlation time of 90 samples (3 min, a twentieth of the run):
  // the residuals ask for the fewest blocks (8 of 225 samples), in which the noise still leaks
  // from block to block. Measured: 91.0-94.2 %: a shortfall, held here to 88 % (2.7 sd of
  // binomial scatter below the lowest measured) so that it cannot grow unnoticed.
  const Coverage c = Measure(OffsetRule::kFitted, Ar1{0.05, 90.0}, 1, kDatasets, 7000);
  Print("fitted offset, one run, AR(1) tau 90 samples", c);
  ExpectWithin(c, "fitted, tau 90", 0.88);
}

}  // namespace
}  // namespace rlg::model

namespace rlg::model {
namespace {

TEST(ModelCoverage, TheTemperatureTimesGradientProductsIntervalsHoldTheTruthOnSoaksAndRamps) {
  // The Langmuir term's form (a quadratic in T1, the gradient T2 - T1 and their product) on three
  // soaks and three ramps at 10 s (tests/model/poly_truth.h), AR(1) noise of 0.01 °/h with a
  // 60 s correlation time; six runs, so the errors are clustered over blocks of the runs.
  // Measured: 94.2-96.8 % (the white-noise formula: 39-47 %).
  std::vector<sim::Run> data = {ChamberRun("soak-30", -30, -30, 0, 10.0), ChamberRun("soak+10", 10, 10, 0, 10.0),
                                ChamberRun("soak+50", 50, 50, 0, 10.0),   ChamberRun("up", -20, 40, 1.0, 10.0),
                                ChamberRun("down", 45, -15, -1.0, 10.0),  ChamberRun("up-slow", 0, 30, 0.5, 10.0)};
  std::vector<const sim::Run*> runs;
  for (const auto& r : data) runs.push_back(&r);
  PolySpec spec = SpecFor(runs, 2, OffsetRule::kFitted,
                          {{TermKind::kGradient, "T2", 0.0, 0.0, {}}, *ParseTerm("T1*(T2-T1)", "T1", nullptr)}, 20.0);
  spec.extrapolate = true;  // the truth's factors are not held to a range
  Eigen::VectorXd truth(5);
  truth << 0.9, 0.006, -8e-5, 0.45, 0.0018;
  PolyFitOptions o;
  o.order = 2;
  o.reference_C = 20.0;
  o.terms = {"gradient:T2", "T1*(T2-T1)"};
  o.extrapolate = true;
  const Coverage c = Measure(data, spec, truth, o, Ar1{0.01, 6.0}, kDatasets, 8000);
  Print("fitted offset, T1*(T2-T1), 3 soaks + 3 ramps, AR(1) tau 6 samples", c);
  ExpectWithin(c, "product", kLow);
}

}  // namespace
}  // namespace rlg::model
