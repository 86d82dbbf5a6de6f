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

#include "diagnosis/statistics/ar_noise.h"

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

/// Generalised least squares by prewhitening (Cochrane & Orcutt 1949; the conditional likelihood
/// of Box & Jenkins): the bias noise of a gyro is not white (bias instability drifts for an
/// hour), and ordinary least squares would weigh a slowly varying regressor as if every fit
/// block were independent. With `ar` the autoregressive model of the residuals
/// (statistics/ar_noise.h), each run's y and columns become
///     v'_k = v_k - sum_{i=1..p} phi_i v_{k-i},   k = p .. n_r - 1
/// (the first p rows dropped), whose errors are the model's white innovations (sd ar.sigma). A
/// run's offset c_r becomes (1 - sum phi) c_r, still a constant, so FitBias's centring still
/// removes it. The prior weights, set against rows of sd `row_noise` (°/h), are rescaled to rows
/// of sd ar.sigma, so each prior keeps its sd. Unchanged for an ar of sigma 0 (no residual).
BiasDesign Prewhiten(const BiasDesign& d, const ArModel& ar, double row_noise);

/// One series prewhitened as Prewhiten does a run's: n - p values (none for n <= p).
Eigen::VectorXd ArInnovations(const ArModel& ar, const Eigen::Ref<const Eigen::VectorXd>& v);

/// Residuals on data not used for the fit, per run (empty for runs not scored):
///   - with held-out runs, beta from the fit runs predicting each held-out run;
///   - with one fit run and none held out, its in-sample residual;
///   - otherwise leave-one-run-out: each fit run predicted by beta from the others.
std::vector<Eigen::VectorXd> HeldOutBias(const BiasDesign& d, const std::vector<int>& fit, const std::vector<int>& held);

/// Two-fold cross-validation in time over `runs`: each run's rows cut into `pieces` equal
/// spans (each its own offset), the even spans of every run fitted to predict the odd ones and
/// the odd the even. Per run (empty for runs not listed) the prediction error of each row from the
/// fold it is not in, about its span's own mean. Every fold holds a part of every run, so an
/// effect that one run excites and another does not is fitted and scored on both: with two runs,
/// one a soak, leaving one run out fits it on the soak alone. For residuals that are white
/// (a prewhitened design); neighbouring spans of drifting residuals would share their drift.
std::vector<Eigen::VectorXd> CrossValidatedInTime(const BiasDesign& d, const std::vector<int>& runs, int pieces);

}  // namespace rlg::diagnosis
