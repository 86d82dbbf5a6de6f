#include "validation/plan_screen.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

#include "sim/errors.h"

namespace rlg::validation {

ScreenNoise NoiseForScreen(const sim::GyroNoiseParams& noise, double dt_s, bool power_on, double n_b0) {
  ScreenNoise s;
  const double arw_dph = 60.0 * noise.arw_deg_per_sqrt_h;  // °/√h -> °/h √s
  s.white_var = arw_dph * arw_dph / dt_s;
  s.offset_var = noise.bias_instability_dph * noise.bias_instability_dph;
  if (power_on && n_b0 > 0.0) {
    s.offset_var += s.white_var / n_b0;
  } else if (!power_on) {
    s.offset_var += noise.turn_on_sigma_dph * noise.turn_on_sigma_dph;
  }
  return s;
}

Eigen::MatrixXd InformationMatrix(const std::vector<Eigen::MatrixXd>& runs, const std::vector<ScreenNoise>& noises) {
  if (runs.empty() || runs.size() != noises.size()) {
    throw InputError("the screen's information matrix needs at least one run, and one noise per run");
  }
  const Eigen::Index p = runs.front().cols();
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(p, p);
  for (size_t r = 0; r < runs.size(); ++r) {
    const Eigen::MatrixXd& X = runs[r];
    const ScreenNoise& noise = noises[r];
    if (!noise.IsValid()) {
      throw InputError(fmt::format("the screen needs white noise (ARW > 0); got sigma_w² = {:g}", noise.white_var));
    }
    const double n = static_cast<double>(X.rows());
    const Eigen::VectorXd s = X.colwise().sum().transpose();
    const double c = noise.offset_var / (noise.white_var + n * noise.offset_var);
    J.noalias() += (X.transpose() * X - c * s * s.transpose()) / noise.white_var;
  }
  return J;
}

double CoefficientVariance(const Eigen::MatrixXd& J, const Eigen::VectorXd& xbar) {
  // Scaled to a unit diagonal, so that the regressors' units (°C, °C², °C³ ...) do not decide
  // what counts as singular.
  Eigen::VectorXd d = J.diagonal();
  for (Eigen::Index i = 0; i < d.size(); ++i) {
    if (!(d(i) > 0.0)) throw NumericalError(fmt::format("the screen's information matrix has no information on coefficient {}", i + 1));
    d(i) = 1.0 / std::sqrt(d(i));
  }
  const Eigen::MatrixXd S = d.asDiagonal() * J * d.asDiagonal();
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(S);
  const Eigen::VectorXd D = ldlt.vectorD();
  if (ldlt.info() != Eigen::Success || D.minCoeff() <= 1e-12 * D.maxCoeff()) {
    throw NumericalError("the protocol cannot identify the model's coefficients (singular information matrix)");
  }
  const Eigen::VectorXd z = d.asDiagonal() * xbar;
  return z.dot(ldlt.solve(z));
}

double MaxAbsNormalQuantile(const std::vector<double>& m, const std::vector<double>& v, double q) {
  if (m.size() != v.size() || m.empty() || !(q > 0.0 && q < 1.0)) {
    throw InputError("MaxAbsNormalQuantile: one mean and variance per term, and q in (0, 1)");
  }
  auto cdf = [&](double x) {
    double p = 1.0;
    for (size_t s = 0; s < m.size(); ++s) {
      const double sd = std::sqrt(std::max(v[s], 0.0));
      if (sd == 0.0) {
        p *= std::abs(m[s]) <= x ? 1.0 : 0.0;
      } else {
        p *= 0.5 * (std::erfc(-(x - m[s]) / (sd * M_SQRT2)) - std::erfc(-(-x - m[s]) / (sd * M_SQRT2)));
      }
    }
    return p;
  };
  double lo = 0.0, hi = 0.0;
  for (size_t s = 0; s < m.size(); ++s) hi = std::max(hi, std::abs(m[s]) + 10.0 * std::sqrt(std::max(v[s], 0.0)));
  if (hi == 0.0) return 0.0;
  while (cdf(hi) < q) hi *= 2.0;
  for (int it = 0; it < 200 && hi - lo > 1e-12 * hi; ++it) {
    const double mid = 0.5 * (lo + hi);
    (cdf(mid) < q ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace rlg::validation
