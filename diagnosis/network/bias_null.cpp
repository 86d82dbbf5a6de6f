#include "diagnosis/network/bias_null.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "diagnosis/network/bias_design.h"
#include "diagnosis/network/bias_search.h"
#include "diagnosis/statistics/score.h"
#include "sim/noise.h"

namespace rlg::diagnosis {

NullBootstrap NullBiasThreshold(const Problem& p, const Model& m, const std::vector<Prediction>& pred) {
  const BiasDesign base = Design(p, m, pred, {});
  const Eigen::VectorXd beta = FitBias(base, p.fit);
  std::vector<double> best;
  ShapeProjections shared;  // the replicates' shape grids: the same tracks and regressors in each
  for (int b = 0; b < p.options.null_replicates; ++b) {
    std::vector<Eigen::VectorXd> y(p.runs.size());
    for (size_t r = 0; r < p.runs.size(); ++r) {
      sim::GyroNoise noise(p.nominal.noise, p.runs[r].sample_period_s, static_cast<uint64_t>(b) + 1, r);
      std::vector<double> n(p.runs[r].run->size());
      for (double& v : n) v = noise.Sample(0.0);
      y[r] = base.X[r] * beta + BlockMeans(p, n, static_cast<int>(r));
    }
    double top = -std::numeric_limits<double>::infinity();
    for (const auto& c : SearchBias(p, m, pred, {}, {}, &y, &shared).candidates)
      if (c.heldout_gain > p.options.min_heldout_gain) top = std::max(top, c.score);
    best.push_back(top);
  }
  NullBootstrap out;
  out.replicates = static_cast<int>(best.size());
  // The largest of the replicates: with 40 of them, a null dataset beats it ~2.5 % of the time.
  out.threshold = NullThreshold(best, p.options.min_score);
  out.replicate_scores = std::move(best);
  return out;
}

std::string NullBootstrapNote(const Problem& p, const NullBootstrap& null) {
  const auto& best = null.replicate_scores;
  const auto passed = std::count_if(best.begin(), best.end(), [](double v) { return std::isfinite(v); });
  return fmt::format("bias acceptance: score >= {:.1f}, the best bias candidate's score on {} null replicates "
                     "(calibrated model + the gyro file's noise; in {} of them some candidate also passed the held-out "
                     "test); the information criterion alone asks {:.0f}",
                     null.threshold, best.size(), passed, p.options.min_score);
}

}  // namespace rlg::diagnosis
