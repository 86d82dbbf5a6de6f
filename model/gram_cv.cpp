#include "model/gram_cv.h"

#include <cmath>
#include <limits>

namespace rlg::model {

GramCv::GramCv(const std::vector<RunFoldGram>& pieces, const std::vector<Eigen::VectorXd>& b0_means, size_t folds,
               bool power_on) {
  const Eigen::Index m = pieces.empty() ? 0 : pieces.front().gram.rows();
  held_.assign(folds, Eigen::MatrixXd::Zero(m, m));
  count_.assign(folds, 0.0);
  for (const RunFoldGram& p : pieces) {
    const double n = p.gram(0, 0);
    count_[p.fold] += n;
    if (!power_on) {
      held_[p.fold] += p.gram;
      continue;
    }
    const Eigen::VectorXd& g0 = b0_means[p.run];
    const Eigen::VectorXd s = p.gram.col(0);
    Eigen::MatrixXd referred = p.gram - s * g0.transpose() - g0 * s.transpose() + n * g0 * g0.transpose();
    referred.row(0).setZero();
    referred.col(0).setZero();
    held_[p.fold] += referred;
  }
  total_ = Eigen::MatrixXd::Zero(m, m);
  for (const auto& h : held_) total_ += h;
  for (double c : count_) samples_ += c;
  // Unit mean square per column (a zero column stays zero and is never solvable); the bias in °/h.
  Eigen::VectorXd scale = Eigen::VectorXd::Ones(m);
  for (Eigen::Index j = 0; j + 1 < m; ++j) {
    const double ms = samples_ > 0.0 ? total_(j, j) / samples_ : 0.0;
    scale[j] = ms > 0.0 ? 1.0 / std::sqrt(ms) : 1.0;
  }
  total_ = scale.asDiagonal() * total_ * scale.asDiagonal();
  for (auto& h : held_) h = scale.asDiagonal() * h * scale.asDiagonal();
}

CvScore GramCv::Score(const std::vector<int>& columns) const {
  CvScore score;
  const auto p = static_cast<Eigen::Index>(columns.size());
  const Eigen::Index y = total_.rows() - 1;
  double sum = 0.0;
  Eigen::MatrixXd A(p, p), Ak(p, p);
  Eigen::VectorXd b(p), bk(p);
  for (size_t k = 0; k < held_.size(); ++k) {
    const Eigen::MatrixXd& H = held_[k];
    for (Eigen::Index i = 0; i < p; ++i) {
      const Eigen::Index ci = columns[static_cast<size_t>(i)];
      bk[i] = H(ci, y);
      b[i] = total_(ci, y) - bk[i];
      for (Eigen::Index j = 0; j < p; ++j) {
        const Eigen::Index cj = columns[static_cast<size_t>(j)];
        Ak(i, j) = H(ci, cj);
        A(i, j) = total_(ci, cj) - Ak(i, j);
      }
    }
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(A);
    const Eigen::VectorXd d = ldlt.vectorD();
    if (ldlt.info() != Eigen::Success || p == 0 || !(d.minCoeff() > kMinPivotRatio * d.cwiseAbs().maxCoeff())) {
      score.rms = std::numeric_limits<double>::infinity();
      score.fold_ms.assign(held_.size(), score.rms);
      score.fold_sse.assign(held_.size(), score.rms);
      return score;
    }
    const Eigen::VectorXd beta = ldlt.solve(b);
    // Cancellation can leave a hair below zero for a fold the model fits exactly.
    const double sse = std::max(0.0, H(y, y) - 2.0 * beta.dot(bk) + beta.dot(Ak * beta));
    score.fold_sse.push_back(sse);
    score.fold_ms.push_back(count_[k] > 0.0 ? sse / count_[k] : 0.0);
    sum += sse;
  }
  score.rms = std::sqrt(sum / std::max(samples_, 1.0));
  return score;
}

}  // namespace rlg::model
