#pragma once
/// What a column adds to a least-squares fit: its part off the span of the regressors already
/// in, and the drop of the residual sum of squares when it joins (Frisch-Waugh-Lovell):
///
///   x_c = the column centred per run,  x = x_c - Q Q' x_c,  gain = (x'e)² / x'x
///
/// Q (rows x rank) an orthonormal basis of the centred regressors' span and e the fit's residual
/// (orthogonal to that span). A column that is a few steps (a mode index: constant between
/// hops) is kept as its steps: per step its rows and its centred value, and q = Q'x_c, its
/// coordinates in the span; then x'x = x_c'x_c - q'q and x'e = x_c'e - q'(Q'e), where x_c'e is
/// a sum over the steps of differences of e's prefix sums. Its cost is then the steps', not the
/// rows' (a bias null bootstrap asks for thousands of a shape search's columns).

#include <Eigen/Core>
#include <cstddef>
#include <utility>
#include <vector>

namespace rlg::diagnosis {

/// A column projected off the span, row by row (x) or as steps (steps, q).
struct OffSpan {
  struct Step {
    Eigen::Index begin = 0, end = 0;  ///< rows [begin, end) of the runs stacked
    double value = 0.0;               ///< the column there, less its run's mean
  };
  Eigen::VectorXd x;         ///< the column centred per run, less its projection (empty as steps)
  std::vector<Step> steps;   ///< or the column as steps ...
  Eigen::VectorXd q;         ///< ... and Q'x_c
  double xx = 0.0;           ///< x'x
  bool within_span = false;  ///< x is round-off: the column adds nothing (gain 0)
  bool none = false;         ///< no column (gain -1)
  /// What keeping it costs, in doubles.
  size_t Doubles() const { return static_cast<size_t>(x.size() + q.size()) + 3 * steps.size(); }
};

/// Gains of columns against one fit (its span and residual).
class SpanComplement {
 public:
  /// Q: rows x rank with orthonormal columns; e: the residual, rows long.
  SpanComplement(Eigen::MatrixXd Q, Eigen::VectorXd e);
  /// The column given per run (`runs`, each a pointer and a length; their lengths sum to rows).
  /// As steps when it has at most one per four rows (a step costs a rank-vector sum where a row
  /// costs two: 8x fewer operations at least) and x'x is above 1e-6 of x_c'x_c (the round-off of
  /// x_c'x_c - q'q is 1e-16 of x_c'x_c: kept below 1e-10 of the result); else row by row, where
  /// x'x at most 1e-12 of x_c'x_c is within the span.
  OffSpan Project(const std::vector<std::pair<const double*, size_t>>& runs) const;
  /// (x'e)² / x'x; 0 within the span, -1 for none.
  double Gain(const OffSpan& c) const;
  Eigen::Index rows() const { return Q_.rows(); }
  Eigen::Index rank() const { return Q_.cols(); }

 private:
  bool Steps(const std::vector<std::pair<const double*, size_t>>& runs, OffSpan* out) const;
  Eigen::MatrixXd Q_;
  Eigen::VectorXd e_;
  Eigen::MatrixXd Q_prefix_;  // column i: the sum of Q's first i rows
  Eigen::VectorXd e_prefix_;  // [i]: the sum of e's first i entries
  Eigen::VectorXd Qe_;        // Q'e
};

}  // namespace rlg::diagnosis
