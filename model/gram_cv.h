#pragma once
/// Cross-validation from sufficient statistics: the score of any subset of a library of
/// regressor columns without another pass over the samples.
///
/// The training samples' library columns x (L of them; column 0 the constant 1) and bias y are
/// reduced, per fold k, to the Gram matrix of the fold's held-out samples
///
///   S_k = [X_k y_k]^T [X_k y_k]     ((L + 1) x (L + 1): the bias last),   S = sum_k S_k.
///
/// The model of columns J fitted without fold k is beta_k = (S - S_k)[J,J]^-1 (S - S_k)[J,y],
/// and its held-out sum of squares is
///
///   SSE_k = S_k[y,y] - 2 beta_k . S_k[J,y] + beta_k^T S_k[J,J] beta_k,
///
/// so one candidate costs O(K |J|^3) for K folds, whatever the number of samples.
///
/// A power-on offset refers a run's bias and columns to their means over its B0 window (g0,
/// with B0 among them: model/causal_regressors.h). That is linear, so the referred Gram of a
/// run's samples in a fold follows from the raw one: with s = S_rk[:, 0] (the column sums, the
/// constant being column 0) and n = S_rk[0, 0],
///
///   sum (z - g0)(z - g0)^T = S_rk - s g0^T - g0 s^T + n g0 g0^T,    z = (x, y);
///
/// the constant column is then zero and no model of that offset uses it.
///
/// Columns (not the bias) are scaled to unit mean square over all samples before any solve (the Gram of a
/// fifth power of a temperature is otherwise 1e16 times that of a gradient). A training Gram
/// whose LDLT pivots fall below kMinPivotRatio of the largest (a scaled condition number of
/// the regressors above ~1e6) cannot be solved reliably: such a candidate scores +inf in every
/// fold, and the search moves past it.

#include <Eigen/Dense>
#include <vector>

namespace rlg::model {

/// A cross-validation score: the RMS over every held-out sample, and each fold's mean square
/// and sum of squares.
struct CvScore {
  double rms = 0.0;
  std::vector<double> fold_ms;
  std::vector<double> fold_sse;
};

/// The held-out samples' raw Gram of one run in one fold (column 0 the constant, the bias
/// last), and the run's means over its B0 window of the same columns (for a power-on offset).
struct RunFoldGram {
  size_t run = 0;
  size_t fold = 0;
  Eigen::MatrixXd gram;
};

class GramCv {
 public:
  /// [est] The smallest LDLT pivot of a scaled training Gram, relative to the largest, that is
  /// solved: 1e-12 is a scaled condition number of ~1e6 for the regressors themselves, where
  /// the normal equations still give about 4 correct digits.
  static constexpr double kMinPivotRatio = 1e-12;

  /// From the raw Grams of every (run, fold) piece; `b0_means[r]` the window means of run r's
  /// columns and bias (used when `power_on`). `folds` folds in all.
  GramCv(const std::vector<RunFoldGram>& pieces, const std::vector<Eigen::VectorXd>& b0_means, size_t folds,
         bool power_on);

  /// The score of the model of `columns` (indices into the library; with a power-on offset
  /// never 0). rms = +inf when a fold's training Gram cannot be solved.
  CvScore Score(const std::vector<int>& columns) const;

  size_t folds() const { return held_.size(); }
  double samples() const { return samples_; }

 private:
  std::vector<Eigen::MatrixXd> held_;  ///< scaled S_k
  Eigen::MatrixXd total_;              ///< scaled S
  std::vector<double> count_;
  double samples_ = 0.0;
};

}  // namespace rlg::model
