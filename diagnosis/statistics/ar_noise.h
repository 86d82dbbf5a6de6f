#pragma once
/// An autoregressive model of a fit's residuals, for the parametric bootstrap of a diagnosis
/// without a thermal network (without_network/null.h). A gyro's bias residual is autocorrelated (bias
/// instability, slow misfit), so replicates made of independent draws, or of residuals resampled
/// one at a time, would be far quieter at low frequencies than the data, and a slowly varying
/// candidate (hysteresis, a long lag) would look significant on noise alone. The replicates
/// are drawn from an AR(p) process fitted to the residuals instead:
///
///     e_k = sum_{i=1..p} phi_i e_{k-i} + sigma u_k,     u_k independent standard normal
///
/// Fitted by Yule-Walker: the biased autocovariances c_h = sum e_k e_{k+h} / N, pooled over the
/// segments given (each about its own mean; products never span two segments; N all values),
/// solved by the Levinson-Durbin recursion, which keeps the process stationary. The order p in
/// 0..max_order is the one of least AIC, N ln sigma_p² + 2 p. Pure: no state but the Rng given.

#include <vector>

#include "sim/noise.h"

namespace rlg::diagnosis {

/// The highest order fitted to a bias residual on 10 s blocks: an AR(10) follows a bias
/// instability of an hour's correlation time and the white noise above it (the searches with
/// and without a thermal network, network/bias_search.cpp and without_network/null.cpp).
inline constexpr int kMaxBiasArOrder = 10;

struct ArModel {
  std::vector<double> phi;  ///< phi_1..phi_p (empty: white noise)
  double sigma = 0.0;       ///< innovation sd (unit of the residuals)
  /// Standard deviation of the stationary process (unit of the residuals): sigma over
  /// sqrt(prod (1 - k_i²)) of the reflection coefficients k_i.
  double sd = 0.0;
  /// Lag-1 autocorrelation of the fitted process.
  double rho1 = 0.0;
};

/// The model of least AIC over orders 0..max_order (at most a tenth of the values, at least 0).
/// A model of sigma 0 for fewer than 3 values or constant segments.
ArModel FitAr(const std::vector<std::vector<double>>& segments, int max_order);

/// The Yule-Walker model of exactly `order` (capped as FitAr caps it), for comparing the
/// likelihoods of several fits with one noise model each: phi holds `order` values, zeros where
/// the recursion stopped early (a perfectly predictable series), so every model so fitted drops
/// the same first values when it prewhitens.
ArModel FitArOfOrder(const std::vector<std::vector<double>>& segments, int order);

/// n values of the process from `rng`, after a burn-in of max(n, 500) values from zero (so that
/// a slowly decorrelating process has reached its stationary spread).
std::vector<double> SimulateAr(const ArModel& m, size_t n, sim::Rng& rng);

}  // namespace rlg::diagnosis
