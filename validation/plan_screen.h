#pragma once
/// The plan's analytic screen (docs/plan.md): what a calibration protocol leaves in service,
/// predicted without a Monte Carlo from the linearised model y = X beta + e, for the nominal
/// gyro.
///
/// Noise (from the gyro's noise model, sim/noise.h), in °/h:
///   sigma_w² = (60 ARW)² / dt          white rate noise of one sample (ARW in °/√h, dt in s)
///   sigma_o² = BI² + sigma_w² / n_B0   (power-on offset)
///   sigma_o² = BI² + TO²               (fitted offset)
///                                      one offset per run: the bias instability BI (°/h) as a
///                                      run-wide wander, and the error of the B0 window mean
///                                      (n_B0 samples) that every sample of y = B - B0 carries,
///                                      or the turn-on bias TO that B0 would have removed
/// so a run r of n_r samples has Cov(e_r) = sigma_w² I + sigma_o² 1 1^T, and the information
/// matrix of the calibration runs, with X_r their regressor rows and s_r = X_r^T 1, is
///
///   J = sum_r X_r^T Cov(e_r)^-1 X_r = sum_r (X_r^T X_r - c_r s_r s_r^T) / sigma_w²,
///       c_r = sigma_o² / (sigma_w² + n_r sigma_o²)                      [(°/h)^-2]
///
/// (Sherman-Morrison). A service run s with mean regressor row xbar_s (n_s samples) is left,
/// after compensation, with a run-mean bias of variance
///
///   v_s = xbar_s^T J^-1 xbar_s + sigma_w² / n_s + sigma_o²              [(°/h)²]
///
/// the coefficients' error carried into service plus the service run's own noise. J^-1 is the
/// covariance of the best linear unbiased fit (GLS); the plan's fits are least squares, which
/// attain it under white noise and do no better otherwise, so v_s is a lower bound there.
/// Information adds over runs: a protocol with more runs never has a larger v_s.
///
/// The screen's |bias after| of service run s is |m_s + N(0, v_s)|, m_s the compensated
/// run-mean bias of the noise-free nominal gyro fitted on the noise-free protocol (what the
/// model cannot represent, extrapolation included). A gyro's score is the largest over the
/// service runs; taking the runs as independent, its quantile q solves
///
///   prod_s [Phi((x - m_s)/sqrt(v_s)) - Phi((-x - m_s)/sqrt(v_s))] = q.
///
/// The screen knows neither part-to-part spread nor noise in the temperature readings: the
/// Monte Carlo beside it does, and their ratio says how much those add.

#include <Eigen/Dense>
#include <vector>

#include "sim/noise.h"

namespace rlg::validation {

struct ScreenNoise {
  double white_var = 0.0;   ///< sigma_w², (°/h)² per sample
  double offset_var = 0.0;  ///< sigma_o², (°/h)² per run

  bool IsValid() const { return white_var > 0.0 && offset_var >= 0.0; }
};

/// sigma_w² and sigma_o² above for samples of dt_s, with or without a B0 window of n_b0 samples
/// (a fitted offset also carries the turn-on bias, which B0 removes for a power-on offset).
ScreenNoise NoiseForScreen(const sim::GyroNoiseParams& noise, double dt_s, bool power_on, double n_b0);

/// J above from the calibration runs' regressor rows (one matrix per run, rows = samples) and
/// each run's noise.
Eigen::MatrixXd InformationMatrix(const std::vector<Eigen::MatrixXd>& runs, const std::vector<ScreenNoise>& noise);

/// xbar^T J^-1 xbar (J inverted on its diagonal scaling; NumericalError when J is singular).
double CoefficientVariance(const Eigen::MatrixXd& J, const Eigen::VectorXd& xbar);

/// The quantile q in (0, 1) of max_s |m_s + N(0, v_s)| for independent terms (bisection to 1e-12
/// relative).
double MaxAbsNormalQuantile(const std::vector<double>& m, const std::vector<double>& v, double q);

}  // namespace rlg::validation
