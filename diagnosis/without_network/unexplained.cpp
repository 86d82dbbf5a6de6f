#include "diagnosis/without_network/unexplained.h"

#include <algorithm>
#include <cmath>

#include "diagnosis/without_network/null.h"
#include "diagnosis/without_network/search.h"

namespace rlg::diagnosis {

namespace {

/// Replicates of the test per null replicate of the acceptance score (without_network/null.h): the gate
/// is the largest of 5 R (200 by default), a 1-in-201 chance on noise alone if its noise model were
/// exact. It is a little quiet: the full model's columns take up part of the noise's slow
/// part. On data made without any term and AR(1) noise of 2 and 10 min correlation
/// (tests/diagnosis/test_diagnose_measured.cpp, 40 seeds each), the largest of 40 replicates called
/// 3 and 2 datasets unexplained, the largest of 200 none and 1.
constexpr int kGateReplicatesPerNull = 5;

/// The largest |r| of a residual with the unit's covariates (0 when none is defined), and which
/// covariate with its sign.
struct Largest {
  double abs_r = 0.0, r = 0.0;
  std::string covariate;
};
Largest LargestOf(const std::map<std::string, std::vector<double>>& covariates, const Eigen::VectorXd& e) {
  const std::vector<double> v(e.data(), e.data() + e.size());
  Largest top;
  for (const auto& [name, values] : covariates) {
    const double r = Correlation(v, values);
    if (std::isfinite(r) && std::abs(r) > top.abs_r) top = {std::abs(r), r, name};
  }
  return top;
}
double LargestCorrelation(const std::map<std::string, std::vector<double>>& covariates, const Eigen::VectorXd& e) {
  return LargestOf(covariates, e).abs_r;
}

/// The largest over the scored units of the residuals of the model on `y`.
double LargestCorrelation(const MeasuredProblem& p, const std::vector<RunColumns>& model_columns, const RunColumns& y) {
  const MeasuredFit fit = FitColumns(p, model_columns, y);
  double top = 0.0;
  for (int u : p.Scored())
    top = std::max(top, LargestCorrelation(MeasuredCovariates(p, u), fit.held_residuals[static_cast<size_t>(u)]));
  return top;
}

}  // namespace

std::map<std::string, std::vector<double>> MeasuredCovariates(const MeasuredProblem& p, int u) {
  const MeasuredUnit& unit = p.units[static_cast<size_t>(u)];
  const auto r = static_cast<size_t>(unit.run);
  const auto c = static_cast<Eigen::Index>(p.channel_index);
  std::vector<double> T, rate, heating;
  for (size_t k : unit.blocks) {
    const double dTdt = 60.0 * p.Tdot[r](c, static_cast<Eigen::Index>(k));
    T.push_back(p.T[r](c, static_cast<Eigen::Index>(k)));
    rate.push_back(dTdt);
    heating.push_back(dTdt > 0.0 ? 1.0 : dTdt < 0.0 ? -1.0 : 0.0);
  }
  return {{p.channel, T}, {"d" + p.channel + "/dt", rate}, {"heating " + p.channel, heating}};
}

MeasuredUnexplained FindMeasuredUnexplained(const MeasuredProblem& p, const std::vector<RunColumns>& model_columns,
                                            const std::vector<RunColumns>& full_columns, const UnexplainedOptions& o) {
  MeasuredUnexplained out;
  const ArModel noise = ResidualNoise(p, full_columns);
  const auto replicates = DrawReplicates(p, model_columns, noise, kGateReplicatesPerNull * p.options.null_replicates, 1);
  out.replicates = static_cast<int>(replicates.size());
  for (const auto& y : replicates) out.null_correlation = std::max(out.null_correlation, LargestCorrelation(p, model_columns, y));
  const MeasuredFit fit = FitColumns(p, model_columns, p.bias);
  double noise_ss = 0.0;
  size_t score_blocks = 0;
  for (int u : p.Scored()) {
    const MeasuredUnit& unit = p.units[static_cast<size_t>(u)];
    const Eigen::VectorXd& e = fit.held_residuals[static_cast<size_t>(u)];
    ChannelResidual c;
    c.run = unit.prepared.label;
    c.channel = "bias_dph";
    for (size_t k : unit.blocks) c.t_s.push_back(p.block_times[static_cast<size_t>(unit.run)][k]);
    c.residual.assign(e.data(), e.data() + e.size());
    c.covariates = MeasuredCovariates(p, u);
    const double per_score_block = std::round(unit.prepared.score_block_s() / unit.prepared.sample_period_s);
    c.score_block_noise = WhiteNoiseSd(unit.prepared.run->Column("bias_dph")) / std::sqrt(per_score_block);
    c.fit_blocks_per_score = unit.prepared.fit_blocks_per_score;
    const size_t blocks = UnitScoreBlocks(p, e, u).size();
    noise_ss += static_cast<double>(blocks) * c.score_block_noise * c.score_block_noise;
    score_blocks += blocks;
    const Largest top = LargestOf(c.covariates, e);
    if (top.abs_r > out.data_correlation) {
      out.data_correlation = top.abs_r;
      out.data_covariate = top.covariate;
      out.data_r = top.r;
    }
    const double r = top.abs_r;
    if (!(r > out.null_correlation)) continue;
    for (auto& entry : FindUnexplained({c}, o)) out.entries.push_back(std::move(entry));
  }
  out.rms_dph = fit.held_out.rms();
  out.noise_dph = score_blocks > 0 ? std::sqrt(noise_ss / static_cast<double>(score_blocks)) : 0.0;
  return out;
}

}  // namespace rlg::diagnosis
