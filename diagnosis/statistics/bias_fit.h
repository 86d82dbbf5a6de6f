#pragma once
/// The linear bias fit (every bias evaluation; stage 5's candidates and their scores): given the node
/// temperatures, the bias physics is linear in its coefficients, so a model's bias is
///     y_r = X_r beta + c_r + e_r      (per run r: fit-block means, °/h)
/// with global coefficients beta (the baseline terms' and any candidate's), a free offset c_r
/// per run (the B0 analogue: each run's turn-on bias) and, for each coefficient with a prior,
/// an extra row w_j (beta_j - m_j) = 0 (w_j = noise of a fit-block mean / prior sd). Pure
/// linear algebra: no simulation.

#include <Eigen/Core>
#include <vector>

namespace rlg::diagnosis {

struct BiasDesign {
  std::vector<Eigen::MatrixXd> X;  ///< per run: fit blocks x global columns
  std::vector<Eigen::VectorXd> y;  ///< per run: fit-block means of the bias (°/h)
  /// Prior of each global coefficient: mean and weight (0 = free).
  Eigen::VectorXd prior_mean, prior_weight;
};

/// beta fitted on the `train` runs: the per-run offsets removed by centring each run
/// (equivalent to a dummy column per run), the prior rows appended, solved by column-pivoted
/// QR (a column the data and the prior leave undetermined gets 0).
Eigen::VectorXd FitBias(const BiasDesign& d, const std::vector<int>& train);

/// Run r's residual y_r - X_r beta about its own mean (its offset fitted), fit blocks.
Eigen::VectorXd BiasResidual(const BiasDesign& d, const Eigen::VectorXd& beta, int r);

/// Residuals on data not used for the fit, per run (empty for runs not scored):
///   - with held-out runs, beta from the fit runs predicting each held-out run;
///   - with one fit run and none held out, its in-sample residual;
///   - otherwise leave-one-run-out: each fit run predicted by beta from the others.
std::vector<Eigen::VectorXd> HeldOutBias(const BiasDesign& d, const std::vector<int>& fit, const std::vector<int>& held);

}  // namespace rlg::diagnosis
