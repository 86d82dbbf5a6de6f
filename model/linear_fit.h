#pragma once
/// The linear least squares of the model family (model/causal_regressors.h), with errors that
/// hold for the autocorrelated residuals of thermal models.
///
///   y = X beta + e,   y = B (fitted offset) or B - B0 (power-on offset) in °/h, X the regressors
///                     of every training sample (BuildDesign: each run from its power-on)
///
/// Solved by Householder QR on column-scaled X (each column divided by its norm); the condition
/// number is that of the scaled problem (singular values of R). Above max_condition_number the
/// fit is refused with a NumericalError naming the coefficients in the near-null space and what
/// data would tell them apart (`hint`).
///
/// Standard errors. The residuals of a thermal model are strongly autocorrelated (misfit and
/// slow noise wander for minutes to hours), so the white-noise formula sigma² (X^T X)^-1 is far
/// too small: on AR(1) noise of an 18 s correlation time its 95 % intervals held the truth 30-41 %
/// of the time (tests/model/test_model_coverage.cpp). The errors are cluster-robust (sandwich)
/// over clusters of contiguous samples, in the bias-reduced form CR2:
///
///   Cov(beta) = (X^T X)^-1 [sum_g X_g^T A_g e_g e_g^T A_g X_g] (X^T X)^-1,  A_g = (I - H_gg)^-1/2
///
/// (H_gg: the cluster's block of the hat matrix; without it a polynomial's coefficients, which
/// rest on the blocks at the ends of the temperature range, held the truth 85-94 % of the time
/// under white noise), with Student's t at G - 1 degrees of freedom, or fewer where a
/// coefficient rests on a few clusters (Bell and McCaffrey's, at white noise).
/// G clusters: the runs, when the fit has at least min_runs_as_clusters of them (run-to-run
/// changes such as turn-on bias then count); otherwise contiguous blocks of equal sample counts,
/// each at least ten integrated correlation times of the residuals long ((1 + rho) / (1 - rho)
/// samples, rho their lag-1 autocorrelation), from min_blocks (8) to blocks (20) of them, shared
/// among the runs in proportion to their samples (runs never share a block). Measured on one
/// chamber cycle of 1800 samples: 94.0-95.0 % at a correlation time of 9 samples, 91.0-94.2 % at
/// 90 samples (8 blocks of 225: the noise leaks between blocks; slower noise would be covered
/// worse still).
/// A power-on offset adds B0's error, common to a whole run: beta's error has a part
/// -(X^T X)^-1 S_run e_B0 per run (S_run the sum of the run's regressors), whose variance comes
/// from batch means (the variance of the means of consecutive window-long stretches of the
/// run's noise estimates), and Satterthwaite's rule combines the degrees of freedom. The noise
/// estimates are then the residuals of the fit with a free constant per run besides, so that
/// B0's error, a constant the polynomial partly takes up, does not inflate its own estimate.
/// Measured with three power-ons: 93.0-96.8 %; with one run alone, c1 of a cubic 90-94 %.

#include <Eigen/Dense>
#include <functional>
#include <string>
#include <vector>

#include "model/causal_regressors.h"
#include "sim/trace.h"

namespace rlg::model {

/// Which samples a fit uses: per run, one flag per sample (nonzero: used). Empty: every sample.
using RowMask = std::vector<std::vector<char>>;

/// The training data of one model as one linear problem.
struct Design {
  Eigen::MatrixXd X;               ///< n x p regressors
  Eigen::VectorXd y;               ///< bias, or bias - B0, °/h
  std::vector<std::string> names;  ///< p coefficient names
  std::vector<int> run;            ///< each row's run (index into the runs given)
  std::vector<char> in_b0_window;  ///< power-on: rows whose bias made their run's B0
  OffsetRule offset = OffsetRule::kFitted;
};

/// The rows of every run of `runs` (a copy of `regressors` runs over each from its power-on):
/// only those `mask` keeps, every sample when `mask` is empty. A power-on offset takes each
/// run's B0 over all its samples in the window, used or not. InputError naming the run for a
/// missing channel or bias column, or a run shorter than the B0 window.
Design BuildDesign(const std::vector<const sim::Run*>& runs, const CausalRegressors& regressors,
                   const RowMask& mask = {}, const std::string& bias_column = "bias_dph");

struct LinearFitOptions {
  /// A scaled condition number above this means the coefficients are not identifiable.
  double max_condition_number = 1e8;
  /// Compute the cluster-robust errors (a cross-validation fold needs only the coefficients).
  bool errors = true;
  /// Contiguous blocks the training data is cut into for the errors (fewer runs than below):
  /// as many as give blocks of ten correlation times of the residuals, from min_blocks to blocks.
  int blocks = 20;
  int min_blocks = 8;
  /// From this many runs on, the runs are the clusters.
  int min_runs_as_clusters = 8;
  /// What data would separate the coefficients named (the refusal's last part).
  std::function<std::string(const std::vector<std::string>& involved)> hint;
  bool IsValid(std::string* error) const;
};

struct LinearFit {
  Eigen::VectorXd beta;
  Eigen::VectorXd standard_error;        ///< cluster-robust (see above); empty without errors
  Eigen::VectorXd white_standard_error;  ///< the white-noise formula, for comparison only
  double dof = 0.0;                      ///< clusters - 1
  Eigen::VectorXd dof_per_coefficient;   ///< Student's t degrees of freedom of each (at most clusters - 1)
  int clusters = 0;
  std::string stderr_method;             ///< "cluster_runs" or "cluster_blocks"
  double condition_number = 0.0;
  double residual_rms_dph = 0.0;
  double rss = 0.0;
  size_t n = 0;
};

/// The fit of `design`. NumericalError when X has fewer rows than columns, a column that is
/// zero in every row, or a scaled condition number at or above the limit (naming coefficients).
LinearFit FitLinear(const Design& design, const LinearFitOptions& options);

/// t_{(1 + level) / 2, dof}: the factor from a standard error to a two-sided interval.
double StudentQuantile(double level, double dof);

}  // namespace rlg::model
