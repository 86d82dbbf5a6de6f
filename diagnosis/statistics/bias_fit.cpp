#include "diagnosis/statistics/bias_fit.h"

#include <Eigen/QR>

namespace rlg::diagnosis {

Eigen::VectorXd FitBias(const BiasDesign& d, const std::vector<int>& train) {
  const Eigen::Index cols = d.X[train.front()].cols();
  Eigen::Index rows = cols;
  for (int r : train) rows += d.X[r].rows();
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(rows, cols);
  Eigen::VectorXd b(rows);
  A.bottomRows(cols) = d.prior_weight.asDiagonal();
  b.tail(cols) = d.prior_weight.cwiseProduct(d.prior_mean);
  Eigen::Index at = 0;
  for (int r : train) {
    // Per-run offset removed by centring each run (equivalent to a dummy per run).
    const Eigen::RowVectorXd mx = d.X[r].colwise().mean();
    A.middleRows(at, d.X[r].rows()) = d.X[r].rowwise() - mx;
    b.segment(at, d.X[r].rows()) = d.y[r].array() - d.y[r].mean();
    at += d.X[r].rows();
  }
  return A.colPivHouseholderQr().solve(b);
}

Eigen::VectorXd BiasResidual(const BiasDesign& d, const Eigen::VectorXd& beta, int r) {
  Eigen::VectorXd e = d.y[r] - d.X[r] * beta;
  return e.array() - e.mean();
}

std::vector<Eigen::VectorXd> HeldOutBias(const BiasDesign& d, const std::vector<int>& fit, const std::vector<int>& held) {
  std::vector<Eigen::VectorXd> out(d.X.size());
  if (!held.empty()) {
    const Eigen::VectorXd beta = FitBias(d, fit);
    for (int r : held) out[r] = BiasResidual(d, beta, r);
    return out;
  }
  if (fit.size() == 1) {
    out[fit[0]] = BiasResidual(d, FitBias(d, fit), fit[0]);
    return out;
  }
  for (int r : fit) {
    std::vector<int> train;
    for (int q : fit)
      if (q != r) train.push_back(q);
    out[r] = BiasResidual(d, FitBias(d, train), r);
  }
  return out;
}

}  // namespace rlg::diagnosis
