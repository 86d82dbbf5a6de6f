#include "diagnosis/network/bias_design.h"

#include <cmath>

#include "sim/bias_model.h"

namespace rlg::diagnosis {

using sim::GyroConfig;

namespace {

/// The gyro file's values of the baseline bias coefficients, in BiasRegressors' columns (dT,
/// dT², and per Langmuir gradient G and G dT), as a prior with a sd of 100 % of each
/// (order-of-magnitude knowledge: the files mark them [est]): it holds what the data cannot
/// see, as the thermal knobs' prior does. Two discharge legs built alike have gradients the
/// data cannot tell apart; fitted freely, their coefficients came out at -8 and +8.4 °/h/°C
/// (sum 0.45, the truth's) and predicted a held-out run 6x worse than the noise. The dT
/// column also carries what is linear in the bias node's temperature in the Langmuir
/// current term and the path-length control. A zero nominal has no prior (free).
void BaselinePrior(const Problem& p, const GyroConfig& g, Eigen::Index cols, BiasDesign* d) {
  const std::vector<double> mean = sim::BaselineCoefficients(g.bias);
  d->prior_mean = Eigen::VectorXd::Zero(cols);
  d->prior_weight = Eigen::VectorXd::Zero(cols);
  for (size_t j = 0; j < mean.size(); ++j) {
    if (mean[j] == 0.0) continue;
    d->prior_mean[static_cast<Eigen::Index>(j)] = mean[j];
    d->prior_weight[static_cast<Eigen::Index>(j)] = p.bias_block_noise / std::abs(mean[j]);
  }
}

/// Global bias regressors on fit blocks for one run: the baseline physics
/// (sim::BaselineRegressors) plus `extra` columns.
Eigen::MatrixXd BiasRegressors(const GyroConfig& g, const Prediction& p, int r, const std::vector<Extra>& extra) {
  const auto nb = static_cast<Eigen::Index>(p.T.cols());
  const Eigen::Index base = sim::NumBaselineRegressors(g.bias);
  Eigen::MatrixXd X(nb, base + static_cast<Eigen::Index>(extra.size()));
  for (Eigen::Index i = 0; i < nb; ++i) {
    sim::BaselineRegressors(g.bias, p.T.col(i), X.row(i).head(base));
    Eigen::Index c = base;
    for (const auto& f : extra) X(i, c++) = f(p, static_cast<size_t>(i), r);
  }
  return X;
}

Eigen::VectorXd BiasData(const Problem& p, int r) { return BlockMeans(p, p.runs[r].run->columns[p.runs[r].bias_col], r); }

}  // namespace

BiasDesign Design(const Problem& p, const Model& m, const std::vector<Prediction>& pred, const std::vector<Extra>& extra,
                  const std::vector<Eigen::VectorXd>* bias_data) {
  BiasDesign d;
  const GyroConfig g = Build(p.nominal, p.knobs, m);
  d.X.resize(p.runs.size());
  d.y.resize(p.runs.size());
  for (size_t r = 0; r < p.runs.size(); ++r) {
    d.X[r] = BiasRegressors(g, pred[r], static_cast<int>(r), extra);
    d.y[r] = bias_data ? (*bias_data)[r] : BiasData(p, static_cast<int>(r));
  }
  BaselinePrior(p, g, d.X.front().cols(), &d);
  return d;
}

std::vector<Eigen::VectorXd> HeldOutBias(const Problem& p, const BiasDesign& d) { return HeldOutBias(d, p.fit, p.held); }

ResidualFit ScoreBias(const Problem& p, const std::vector<Eigen::VectorXd>& res) {
  std::vector<std::vector<double>> series;
  for (int r : p.Scored()) series.push_back(ToScoreBlocks(p, res[r], r));
  return Summarise(series);
}

}  // namespace rlg::diagnosis
