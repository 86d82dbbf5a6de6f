#include "model/allan.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "sim/errors.h"
#include "sim/stats.h"

namespace rlg::model {

AllanCurve OverlappingAllan(const std::vector<double>& y, double dt_s, int min_clusters) {
  AllanCurve c;
  const size_t n = y.size();
  // Cumulative angle: theta_k = dt sum_{i<k} y_i, so the mean over m samples starting at i is
  // (theta_{i+m} - theta_i) / (m dt).
  std::vector<double> theta(n + 1, 0.0);
  for (size_t i = 0; i < n; ++i) theta[i + 1] = theta[i] + y[i] * dt_s;
  for (size_t m = 1; min_clusters * m <= n; m *= 2) {
    const double tau = static_cast<double>(m) * dt_s;
    const size_t terms = n + 1 - 2 * m;
    double sum = 0.0;
    for (size_t k = 0; k < terms; ++k) {
      const double d = theta[k + 2 * m] - 2.0 * theta[k + m] + theta[k];
      sum += d * d;
    }
    c.tau_s.push_back(tau);
    c.adev.push_back(std::sqrt(sum / (2.0 * tau * tau * static_cast<double>(terms))));
    c.n_samples.push_back(static_cast<double>(terms));
  }
  return c;
}

double SamplePeriod(const std::vector<double>& t_s) {
  if (t_s.size() < 2) throw InputError(fmt::format("a sample period needs two samples; the record has {}", t_s.size()));
  std::vector<double> steps(t_s.size() - 1);
  for (size_t k = 0; k + 1 < t_s.size(); ++k) steps[k] = t_s[k + 1] - t_s[k];
  const auto mid = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
  std::nth_element(steps.begin(), mid, steps.end());
  if (steps.size() % 2 == 1) return *mid;
  const double upper = *mid;
  return 0.5 * (upper + *std::max_element(steps.begin(), mid));
}

namespace {

// Two times that differ by less than this relative amount are the same averaging time: time
// stamps written with 6+ significant digits reproduce a sample period only to ~1e-9.
constexpr double kSameTime = 1e-6;

}  // namespace

bool Stability::adjusted() const { return std::abs(averaging_s - requested_s) > kSameTime * requested_s; }

Stability BiasStability(const std::vector<double>& y, double dt_s, double tau_s, BelowSamplePeriod below) {
  if (!(dt_s > 0.0) || !(tau_s > 0.0)) {
    throw InputError(fmt::format("bias stability needs a positive sample period and averaging time (got {:g} s and {:g} s)",
                                 dt_s, tau_s));
  }
  Stability s;
  s.requested_s = tau_s;
  s.below_sample_period = tau_s < dt_s * (1.0 - kSameTime);
  if (s.below_sample_period && below == BelowSamplePeriod::kRefuse) {
    throw InputError(fmt::format("averaging time {:g} s is below the {:g} s sample period: a stability can be computed "
                                 "over whole samples only, {:g} s or longer",
                                 tau_s, dt_s, dt_s));
  }
  s.samples_per_block = std::max<size_t>(1, static_cast<size_t>(std::llround(tau_s / dt_s)));
  s.averaging_s = static_cast<double>(s.samples_per_block) * dt_s;
  s.blocks = y.size() / s.samples_per_block;
  if (s.blocks < 2) {
    throw InputError(fmt::format("bias stability at {:g} s needs at least two {:g} s blocks; the run has {} samples of {:g} s",
                                 tau_s, s.averaging_s, y.size(), dt_s));
  }
  std::vector<double> means(s.blocks);
  const size_t m = s.samples_per_block;
  for (size_t b = 0; b < s.blocks; ++b) {
    double sum = 0.0;
    for (size_t i = b * m; i < (b + 1) * m; ++i) sum += y[i];
    means[b] = sum / static_cast<double>(m);
  }
  s.sigma = sim::StdDev(means);
  return s;
}

std::string DescribeAveraging(const Stability& s, double dt_s) {
  if (!s.adjusted()) return fmt::format("{:g} s", s.averaging_s);
  if (s.below_sample_period) {
    return fmt::format("{:g} s (one sample: {:g} s is below the {:g} s sample period)", s.averaging_s, s.requested_s, dt_s);
  }
  return fmt::format("{:g} s ({} samples of {:g} s: {:g} s is not a whole number of samples)", s.averaging_s,
                     s.samples_per_block, dt_s, s.requested_s);
}

double AllanVariance(const NoiseTerms& t, double tau) {
  return 3.0 * t.quantization * t.quantization / (tau * tau) + t.arw * t.arw / tau +
         std::pow(0.664 * t.bias_instability, 2) + t.rrw * t.rrw * tau / 3.0;
}

NoiseTerms FitNoiseTerms(const AllanCurve& c) {
  const auto p = static_cast<Eigen::Index>(c.tau_s.size());
  // Basis of sigma²(tau): 1/tau², 1/tau, 1, tau. Coefficients: 3Q², N², (0.664B)², K²/3.
  Eigen::MatrixXd A(p, 4);
  Eigen::VectorXd b(p);
  for (Eigen::Index i = 0; i < p; ++i) {
    const double tau = c.tau_s[i];
    const double avar = c.adev[i] * c.adev[i];
    // Relative error of an Allan variance estimate ~ sqrt(2 m / n) for m samples per cluster;
    // divide rows by avar * that error so each point counts by its own uncertainty.
    const double m = tau / c.tau_s.front();
    const double rel = std::sqrt(std::max(2.0 * m / c.n_samples[i], 1e-12));
    const double w = 1.0 / (avar * rel);
    A.row(i) << w / (tau * tau), w / tau, w, w * tau;
    b[i] = avar * w;
  }
  // Non-negative least squares over 4 terms: try every subset, keep the best feasible fit.
  Eigen::Vector4d best = Eigen::Vector4d::Zero();
  double best_cost = std::numeric_limits<double>::infinity();
  for (int mask = 1; mask < 16; ++mask) {
    std::vector<int> cols;
    for (int j = 0; j < 4; ++j)
      if (mask & (1 << j)) cols.push_back(j);
    if (static_cast<Eigen::Index>(cols.size()) > p) continue;
    Eigen::MatrixXd As(p, static_cast<Eigen::Index>(cols.size()));
    for (size_t j = 0; j < cols.size(); ++j) As.col(static_cast<Eigen::Index>(j)) = A.col(cols[j]);
    const Eigen::VectorXd x = As.colPivHouseholderQr().solve(b);
    if ((x.array() < 0.0).any()) continue;
    const double cost = (As * x - b).squaredNorm();
    if (cost < best_cost) {
      best_cost = cost;
      best.setZero();
      for (size_t j = 0; j < cols.size(); ++j) best[cols[j]] = x[static_cast<Eigen::Index>(j)];
    }
  }
  NoiseTerms t;
  t.quantization = std::sqrt(best[0] / 3.0);
  t.arw = std::sqrt(best[1]);
  t.bias_instability = std::sqrt(best[2]) / 0.664;
  t.rrw = std::sqrt(3.0 * best[3]);
  return t;
}

}  // namespace rlg::model
