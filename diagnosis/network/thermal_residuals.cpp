#include "diagnosis/network/thermal_residuals.h"

#include <algorithm>
#include <cmath>

#include "diagnosis/statistics/bias_fit.h"
#include "diagnosis/statistics/score.h"

namespace rlg::diagnosis {

ThermalResidualSet ThermalResiduals(const Problem& p, const std::vector<Prediction>& pred, const std::vector<int>& which) {
  ThermalResidualSet res(p.runs.size());
  for (int r : which) {
    const auto& run = p.runs[r];
    res[r].resize(p.nominal.sensors.size());
    for (size_t s = 0; s < p.nominal.sensors.size(); ++s) {
      if (run.sensor_col[s] < 0) continue;
      const Eigen::VectorXd& meas = p.measured[r][s];
      std::vector<double>& e = res[r][s];
      e.resize(static_cast<size_t>(meas.size()));
      for (Eigen::Index i = 0; i < meas.size(); ++i) e[static_cast<size_t>(i)] = pred[r].sensor[s][static_cast<size_t>(i)] - meas[i];
    }
  }
  return res;
}

ThermalResidualSet ThermalResiduals(const Problem& p, const Model& m, const std::vector<int>& which) {
  return ThermalResiduals(p, SimulateAll(p, m, which, Sampled::kSensors), which);
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

namespace {

/// One channel's residuals over the runs `which`, a segment per run that has it.
std::vector<std::vector<double>> ChannelSegments(const ThermalResidualSet& res, const std::vector<int>& which, size_t s) {
  std::vector<std::vector<double>> segments;
  for (int r : which)
    if (s < res[r].size() && !res[r][s].empty()) segments.push_back(res[r][s]);
  return segments;
}

/// The sum of squared innovations of one segment; adds their count to *n when given.
double InnovationSsr(const ArModel& ar, const std::vector<double>& v, Eigen::Index* n = nullptr) {
  const Eigen::VectorXd u = ArInnovations(ar, Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())));
  if (n) *n += u.size();
  return u.squaredNorm();
}

}  // namespace

std::vector<int> ThermalArOrders(const ThermalResidualSet& res, const std::vector<int>& which, size_t channels) {
  std::vector<int> orders(channels, 0);
  for (size_t s = 0; s < orders.size(); ++s) {
    const auto segments = ChannelSegments(res, which, s);
    if (!segments.empty()) orders[s] = static_cast<int>(FitAr(segments, kMaxThermalArOrder).phi.size());
  }
  return orders;
}

std::vector<ArModel> ThermalNoiseModels(const ThermalResidualSet& res, const std::vector<int>& which,
                                        const std::vector<int>& orders) {
  std::vector<ArModel> models(orders.size());
  for (size_t s = 0; s < orders.size(); ++s) {
    const auto segments = ChannelSegments(res, which, s);
    if (!segments.empty()) models[s] = FitArOfOrder(segments, orders[s]);
  }
  return models;
}

double ThermalGlsGain(const ThermalResidualSet& base, const ThermalResidualSet& ext, const std::vector<int>& which,
                      const std::vector<int>& orders) {
  const std::vector<ArModel> models = ThermalNoiseModels(ext, which, orders);
  double gain = 0.0;
  for (size_t s = 0; s < orders.size(); ++s) {
    Eigen::Index n = 0;  // ext has as many: one model, the same segments
    ResidualFit before, after;
    for (int r : which) {
      if (s >= ext[r].size() || ext[r][s].empty()) continue;
      before.ssr += InnovationSsr(models[s], base[r][s], &n);
      after.ssr += InnovationSsr(models[s], ext[r][s]);
    }
    before.n = after.n = static_cast<int>(n);
    gain += LogLikelihoodRatio(before, after);
  }
  return gain;
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
