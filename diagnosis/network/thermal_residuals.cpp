#include "diagnosis/network/thermal_residuals.h"

#include <algorithm>

namespace rlg::diagnosis {

ThermalResidualSet ThermalResiduals(const Problem& p, const std::vector<Prediction>& pred, const std::vector<int>& which) {
  ThermalResidualSet res(p.runs.size());
  for (int r : which) {
    const auto& run = p.runs[r];
    res[r].resize(p.nominal.sensors.size());
    for (size_t s = 0; s < p.nominal.sensors.size(); ++s) {
      if (run.sensor_col[s] < 0) continue;
      const Eigen::VectorXd meas = BlockMeans(p, run.run->columns[run.sensor_col[s]], r);
      for (Eigen::Index i = 0; i < meas.size(); ++i) res[r][s].push_back(pred[r].sensor[s][static_cast<size_t>(i)] - meas[i]);
    }
  }
  return res;
}

ThermalResidualSet Difference(ThermalResidualSet a, const ThermalResidualSet& b) {
  for (size_t r = 0; r < a.size(); ++r)
    for (size_t s = 0; s < a[r].size(); ++s)
      for (size_t i = 0; i < a[r][s].size(); ++i) a[r][s][i] -= b[r][s][i];
  return a;
}

double ThermalChi2(const ThermalResidualSet& res, const std::vector<int>& which, const std::vector<double>& channel_var) {
  double chi2 = 0.0;
  for (int r : which)
    for (size_t s = 0; s < res[r].size(); ++s)
      for (double v : res[r][s]) chi2 += v * v / channel_var[s];
  return chi2;
}

std::vector<double> ChannelVariances(const Problem& p, const ThermalResidualSet& res) {
  std::vector<double> var(p.nominal.sensors.size(), kUnitChannelVar);
  for (size_t s = 0; s < p.nominal.sensors.size(); ++s) {
    double ssr = 0.0;
    int n = 0;
    for (int r : p.fit)
      for (double v : res[r][s]) ssr += v * v, ++n;
    if (n > 0) var[s] = std::max(ssr / n, 2.5e-7);
  }
  return var;
}

double ScoreSsr(const Problem& p, const std::vector<double>& residuals, int r, int* n) {
  double ssr = 0.0;
  for (double mean : ToScoreBlocks(p, Eigen::Map<const Eigen::VectorXd>(residuals.data(), static_cast<Eigen::Index>(residuals.size())), r)) {
    ssr += mean * mean;
    if (n) ++*n;
  }
  return ssr;
}

double ThermalScoreSsr(const Problem& p, const ThermalResidualSet& res, const std::vector<int>& which, int* n) {
  double ssr = 0.0;
  for (int r : which)
    for (const auto& channel : res[r]) ssr += ScoreSsr(p, channel, r, n);
  return ssr;
}

}  // namespace rlg::diagnosis
