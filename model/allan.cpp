#include "model/allan.h"

#include <Eigen/Dense>
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

double BiasStability(const std::vector<double>& y, double dt_s, double tau_s) {
  const size_t m = std::max<size_t>(1, static_cast<size_t>(std::llround(tau_s / dt_s)));
  const size_t blocks = y.size() / m;
  if (blocks < 2) {
    throw InputError(fmt::format("bias stability at {:g} s needs at least two {:g} s blocks; the run has {} samples of {:g} s",
                                 tau_s, static_cast<double>(m) * dt_s, y.size(), dt_s));
  }
  std::vector<double> means(blocks);
  for (size_t b = 0; b < blocks; ++b) {
    double sum = 0.0;
    for (size_t i = b * m; i < (b + 1) * m; ++i) sum += y[i];
    means[b] = sum / static_cast<double>(m);
  }
  return sim::StdDev(means);
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
