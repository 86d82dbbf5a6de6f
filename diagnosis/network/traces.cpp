#include "diagnosis/network/traces.h"

#include <cmath>

#include "diagnosis/network/model_residuals.h"
#include "diagnosis/report.h"
#include "diagnosis/network/thermal_residuals.h"

namespace rlg::diagnosis {

namespace {

/// Block means of column `col` of run r.
std::vector<double> ColumnBlockMeans(const Problem& p, int r, int col) {
  const Eigen::VectorXd m = BlockMeans(p, p.runs[r].run->columns[col], r);
  return std::vector<double>(m.data(), m.data() + m.size());
}

/// The unexplained stage's inputs of run r (diagnosis/statistics/unexplained.h): each channel's final
/// residual, its noise, and what it might move with.
void AddChannelResiduals(const Problem& p, int r, const ResidualTrace& tr, std::vector<ChannelResidual>& out) {
  const sim::Run& run = *p.runs[r].run;
  const double per_score_block = std::round(p.runs[r].score_block_s() / p.runs[r].sample_period_s);
  for (size_t s = 0; s < p.nominal.sensors.size(); ++s) {
    const int col = p.runs[r].sensor_col[s];
    if (col < 0) continue;
    ChannelResidual c;
    c.run = p.runs[r].label;
    c.channel = p.nominal.sensors[s].channel;
    c.t_s = tr.t_s;
    c.residual = tr.extended.at(c.channel);
    c.covariates[c.channel] = tr.measured.at(c.channel);
    c.covariates["d" + c.channel + "/dt"] = RatePerMinute(tr.t_s, tr.measured.at(c.channel));
    for (size_t k = 0; k < run.columns.size(); ++k)
      if (run.names[k] == "T_amb" || run.names[k].rfind("P_", 0) == 0)
        c.covariates[run.names[k]] = ColumnBlockMeans(p, r, static_cast<int>(k));
    // White noise from fourth differences (WhiteNoiseSd): a ramp's first differences are its
    // slope, 0.17 °C a sample at 1 °C/min and 10 s, which made every channel look quiet.
    c.score_block_noise = WhiteNoiseSd(run.columns[static_cast<size_t>(col)]) / std::sqrt(per_score_block);
    c.fit_blocks_per_score = p.runs[r].fit_blocks_per_score;
    out.push_back(std::move(c));
  }
}

}  // namespace

Traces MakeTraces(const Problem& p, const Model& baseline, const Model& extended, const std::vector<Extra>& extended_columns) {
  const std::vector<int> all = p.All();
  const ModelResiduals b = ResidualsOf(p, baseline), e = ResidualsOf(p, extended, extended_columns);
  auto negated = [](std::vector<double> v) {  // ThermalResiduals are simulated - measured
    for (double& x : v) x = -x;
    return v;
  };
  Traces out;
  for (int r : all) {
    ResidualTrace tr;
    tr.run = p.runs[r].run->id;
    tr.t_s = p.block_times[r];
    for (size_t s = 0; s < p.nominal.sensors.size(); ++s) {
      if (p.runs[r].sensor_col[s] < 0) continue;
      const std::string& ch = p.nominal.sensors[s].channel;
      tr.measured[ch] = ColumnBlockMeans(p, r, p.runs[r].sensor_col[s]);
      tr.baseline[ch] = negated(b.thermal[r][s]);
      tr.extended[ch] = negated(e.thermal[r][s]);
    }
    AddChannelResiduals(p, r, tr, out.channel_residuals);
    if (p.has_bias && b.bias[r].size() > 0) {
      tr.measured["bias_dph"] = ColumnBlockMeans(p, r, p.runs[r].bias_col);
      tr.baseline["bias_dph"] = std::vector<double>(b.bias[r].data(), b.bias[r].data() + b.bias[r].size());
      tr.extended["bias_dph"] = std::vector<double>(e.bias[r].data(), e.bias[r].data() + e.bias[r].size());
    }
    out.residuals.push_back(std::move(tr));
  }
  return out;
}

}  // namespace rlg::diagnosis
