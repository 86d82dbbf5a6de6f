#include "diagnosis/statistics/bias_fit.h"

#include <Eigen/QR>
#include <algorithm>

namespace rlg::diagnosis {

Eigen::VectorXd FitBias(const BiasDesign& d, const std::vector<int>& train) {
  const Eigen::Index cols = d.X[train.front()].cols();
  Eigen::Index rows = cols;
  for (int r : train) rows += d.X[r].rows();
  Eigen::MatrixXd A(rows, cols);  // every row is set below
  Eigen::VectorXd b(rows);
  A.bottomRows(cols) = d.prior_weight.asDiagonal();
  b.tail(cols) = d.prior_weight.cwiseProduct(d.prior_mean);
  Eigen::Index at = 0;
  for (int r : train) {
    if (d.X[r].rows() == 0) continue;  // a run prewhitening or a cut left empty
    // Per-run offset removed by centring each run (equivalent to a dummy per run).
    const Eigen::RowVectorXd mx = d.X[r].colwise().mean();
    A.middleRows(at, d.X[r].rows()) = d.X[r].rowwise() - mx;
    b.segment(at, d.X[r].rows()) = d.y[r].array() - d.y[r].mean();
    at += d.X[r].rows();
  }
  // Factorised in place, not in a copy of A (the null bootstrap makes thousands of these).
  const Eigen::ColPivHouseholderQR<Eigen::Ref<Eigen::MatrixXd>> qr(A);
  return qr.solve(b);
}

Eigen::VectorXd ArInnovations(const ArModel& ar, const Eigen::Ref<const Eigen::VectorXd>& v) {
  const auto p = static_cast<Eigen::Index>(ar.phi.size());
  if (v.size() <= p) return Eigen::VectorXd();
  const Eigen::Index n = v.size() - p;
  Eigen::VectorXd out = v.tail(n);
  for (Eigen::Index i = 1; i <= p; ++i) out -= ar.phi[static_cast<size_t>(i - 1)] * v.segment(p - i, n);
  return out;
}

BiasDesign Prewhiten(const BiasDesign& d, const ArModel& ar, double row_noise) {
  if (!(ar.sigma > 0.0) || !(row_noise > 0.0)) return d;
  BiasDesign w;
  w.X.resize(d.X.size());
  w.y.resize(d.y.size());
  for (size_t r = 0; r < d.X.size(); ++r) {
    w.y[r] = ArInnovations(ar, d.y[r]);
    w.X[r].resize(w.y[r].size(), d.X[r].cols());
    for (Eigen::Index j = 0; j < d.X[r].cols(); ++j) w.X[r].col(j) = ArInnovations(ar, d.X[r].col(j));
  }
  w.prior_mean = d.prior_mean;
  w.prior_weight = d.prior_weight * (ar.sigma / row_noise);
  return w;
}

Eigen::VectorXd BiasResidual(const BiasDesign& d, const Eigen::VectorXd& beta, int r) {
  Eigen::VectorXd e = d.y[r] - d.X[r] * beta;
  if (e.size() == 0) return e;
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

std::vector<Eigen::VectorXd> CrossValidatedInTime(const BiasDesign& d, const std::vector<int>& runs, int pieces) {
  pieces = std::max(2, pieces);
  struct Span {
    int run;
    Eigen::Index from, rows;
  };
  BiasDesign cut;  // every span a run of its own
  cut.prior_mean = d.prior_mean;
  cut.prior_weight = d.prior_weight;
  std::vector<Span> spans;
  std::vector<int> fold[2];
  for (int r : runs) {
    const Eigen::Index n = d.X[r].rows();
    for (int q = 0; q < pieces; ++q) {
      const Eigen::Index from = n * q / pieces, to = n * (q + 1) / pieces;
      fold[q % 2].push_back(static_cast<int>(spans.size()));
      spans.push_back({r, from, to - from});
      cut.X.push_back(d.X[r].middleRows(from, to - from));
      cut.y.push_back(d.y[r].segment(from, to - from));
    }
  }
  std::vector<Eigen::VectorXd> out(d.X.size());
  for (int r : runs) out[r] = Eigen::VectorXd::Zero(d.X[r].rows());
  for (int f = 0; f < 2; ++f) {
    const Eigen::VectorXd beta = FitBias(cut, fold[f]);
    for (int i : fold[1 - f]) {
      const Span& s = spans[static_cast<size_t>(i)];
      if (s.rows > 0) out[s.run].segment(s.from, s.rows) = BiasResidual(cut, beta, i);
    }
  }
  return out;
}

}  // namespace rlg::diagnosis
