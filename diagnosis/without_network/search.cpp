#include "diagnosis/without_network/search.h"

#include "diagnosis/statistics/score.h"
#include "model/profile_search.h"

namespace rlg::diagnosis {

namespace {

std::vector<const RunColumns*> Pointers(const std::vector<RunColumns>& model_columns, const RunColumns* extra) {
  std::vector<const RunColumns*> out;
  for (const auto& c : model_columns) out.push_back(&c);
  if (extra) out.push_back(extra);
  return out;
}

/// The candidate's profiled parameter (0 when it has none) and its column there.
std::pair<double, RunColumns> Profiled(const MeasuredProblem& p, const std::vector<RunColumns>& model_columns,
                                       const MeasuredCandidate& c, const RunColumns& y) {
  if (c.searched == 0) return {0.0, c.column(0.0)};
  auto ssr = [&](double x) {
    const RunColumns column = c.column(x);
    return InSampleSsr(p, MeasuredDesign(p, Pointers(model_columns, &column), y));
  };
  const double x = model::MinimizeOnLogScale(ssr, c.lo, c.hi).x;
  return {x, c.column(x)};
}

}  // namespace


MeasuredFit FitColumns(const MeasuredProblem& p, const std::vector<RunColumns>& model_columns, const RunColumns& y,
                       const RunColumns* extra) {
  return FitMeasured(p, MeasuredDesign(p, Pointers(model_columns, extra), y));
}

std::vector<MeasuredScored> ScoreMeasured(const MeasuredProblem& p, const std::vector<RunColumns>& model_columns,
                                          const std::vector<MeasuredCandidate>& candidates,
                                          const std::set<CauseTarget>& taken, const RunColumns& y) {
  const MeasuredFit base = FitColumns(p, model_columns, y);
  std::vector<MeasuredScored> out;
  for (const auto& c : candidates) {
    if (taken.count({c.cause, c.target})) continue;
    auto [x, column] = Profiled(p, model_columns, c, y);
    const BiasDesign d = MeasuredDesign(p, Pointers(model_columns, &column), y);
    const MeasuredFit ext = FitMeasured(p, d);
    MeasuredScored s;
    s.candidate.cause = c.cause;
    s.candidate.target = c.target;
    s.candidate.kind = CandidateKind::kBias;
    s.candidate.parameters = c.parameters(FitBias(d, p.fit)[d.X.front().cols() - 1], x);
    s.candidate.score = InformationGain(base.in_sample, ext.in_sample, 1 + c.searched);
    s.candidate.heldout_rms_ratio = HeldOutRmsRatio(base.held_out.ssr, ext.held_out.ssr);
    s.candidate.heldout_gain = LogLikelihoodRatio(base.held_out, ext.held_out);
    s.column = std::move(column);
    out.push_back(std::move(s));
  }
  return out;
}

}  // namespace rlg::diagnosis
