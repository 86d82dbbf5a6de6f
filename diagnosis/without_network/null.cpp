#include "diagnosis/without_network/null.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "diagnosis/without_network/search.h"
#include "diagnosis/progress.h"
#include "diagnosis/statistics/score.h"

namespace rlg::diagnosis {

namespace {

/// The fitted units' in-sample residuals, cut where their counted blocks are not consecutive.
std::vector<std::vector<double>> ResidualSegments(const MeasuredProblem& p, const BiasDesign& d,
                                                  const Eigen::VectorXd& beta) {
  std::vector<std::vector<double>> segments;
  for (int u : p.fit) {
    const Eigen::VectorXd e = BiasResidual(d, beta, u);
    const auto& blocks = p.units[static_cast<size_t>(u)].blocks;
    for (size_t i = 0; i < blocks.size(); ++i) {
      if (i == 0 || blocks[i] != blocks[i - 1] + 1) segments.emplace_back();
      segments.back().push_back(e[static_cast<Eigen::Index>(i)]);
    }
  }
  return segments;
}

}  // namespace

ArModel ResidualNoise(const MeasuredProblem& p, const std::vector<RunColumns>& columns) {
  std::vector<const RunColumns*> pointers;
  for (const auto& c : columns) pointers.push_back(&c);
  const BiasDesign d = MeasuredDesign(p, pointers, p.bias);
  return FitAr(ResidualSegments(p, d, FitBias(d, p.fit)), kMaxBiasArOrder);
}

std::vector<RunColumns> DrawReplicates(const MeasuredProblem& p, const std::vector<RunColumns>& columns,
                                       const ArModel& noise, int count, uint64_t substream) {
  std::vector<const RunColumns*> pointers;
  for (const auto& c : columns) pointers.push_back(&c);
  const Eigen::VectorXd beta = FitBias(MeasuredDesign(p, pointers, p.bias), p.fit);
  std::vector<RunColumns> out;
  for (int b = 0; b < count; ++b) {
    RunColumns y;
    for (size_t r = 0; r < p.runs.size(); ++r) {
      Eigen::VectorXd fitted = Eigen::VectorXd::Zero(p.bias[r].size());
      for (size_t c = 0; c < columns.size(); ++c) fitted += beta[static_cast<Eigen::Index>(c)] * columns[c][r];
      sim::Rng rng(static_cast<uint64_t>(b) + 1, r, substream);
      const std::vector<double> e = SimulateAr(noise, static_cast<size_t>(fitted.size()), rng);
      y.push_back(fitted + Eigen::Map<const Eigen::VectorXd>(e.data(), fitted.size()));
    }
    out.push_back(std::move(y));
  }
  return out;
}

MeasuredNull NullFromResiduals(const MeasuredProblem& p, const std::vector<RunColumns>& model_columns,
                               const std::vector<MeasuredCandidate>& candidates) {
  MeasuredNull out;
  out.noise = ResidualNoise(p, model_columns);
  const Progress progress(p.options.progress);
  std::vector<double> best;
  const std::vector<RunColumns> replicates = DrawReplicates(p, model_columns, out.noise, p.options.null_replicates, 0);
  for (const auto& y : replicates) {
    progress(fmt::format("null bootstrap: replicate {} of {}", best.size() + 1, replicates.size()));
    double top = -std::numeric_limits<double>::infinity();
    for (const auto& s : ScoreMeasured(p, model_columns, candidates, {}, y))
      if (s.candidate.heldout_rms_ratio >= p.options.min_heldout_ratio) top = std::max(top, s.candidate.score);
    best.push_back(top);
  }
  out.bootstrap.replicates = static_cast<int>(best.size());
  out.bootstrap.threshold = NullThreshold(best, p.options.min_score);
  out.bootstrap.replicate_scores = std::move(best);
  return out;
}

std::string MeasuredNullNote(const MeasuredProblem& p, const MeasuredNull& null) {
  const auto& best = null.bootstrap.replicate_scores;
  const auto passed = std::count_if(best.begin(), best.end(), [](double v) { return std::isfinite(v); });
  return fmt::format("acceptance: score >= {:.1f}, the best candidate's score on {} null replicates (the baseline's fit "
                     "plus AR({}) noise fitted to its fit-block residuals: sd {:.3g} °/h, lag-1 correlation {:.2f}; in {} "
                     "of them some candidate also passed the held-out test); the information criterion alone asks {:.0f}",
                     null.bootstrap.threshold, best.size(), null.noise.phi.size(), null.noise.sd, null.noise.rho1, passed,
                     p.options.min_score);
}

}  // namespace rlg::diagnosis
