// DiagnoseWithoutNetwork: the bias search alone over measured channels (diagnose.h), in stages
// like Diagnose's: the problem (without_network/problem.h), the baseline polynomial
// (without_network/baseline.h), residual checks, the null bootstrap (without_network/null.h), the search and
// acceptance (without_network/search.h, statistics/rank.h), what stays (without_network/unexplained.h) and the traces.

#include <algorithm>
#include <fmt/format.h>
#include <limits>
#include <set>

#include "diagnosis/diagnose.h"
#include "diagnosis/without_network/baseline.h"
#include "diagnosis/without_network/candidates.h"
#include "diagnosis/without_network/null.h"
#include "diagnosis/without_network/problem.h"
#include "diagnosis/without_network/search.h"
#include "diagnosis/without_network/unexplained.h"
#include "diagnosis/progress.h"
#include "diagnosis/statistics/rank.h"
#include "diagnosis/statistics/score.h"
#include "diagnosis/statistics/steps.h"
#include "sim/errors.h"
#include "sim/stats.h"

namespace rlg::diagnosis {

namespace {

/// The record before any fit: score-block lengths and the split of a single run.
DiagnosisWithoutNetwork Header(const MeasuredProblem& p) {
  DiagnosisWithoutNetwork dx;
  dx.has_bias = true;
  dx.score_block_s = {std::numeric_limits<double>::infinity(), 0.0};
  for (const auto& u : p.units) {
    dx.score_block_s.first = std::min(dx.score_block_s.first, u.prepared.score_block_s());
    dx.score_block_s.second = std::max(dx.score_block_s.second, u.prepared.score_block_s());
  }
  if (!p.split_note.empty()) dx.notes.push_back(p.split_note);
  dx.thermal_null_bootstrap.threshold = p.options.min_score;  // no thermal search: no replicates
  return dx;
}

/// Stage 3 on the baseline's held-out residuals: Ljung-Box whiteness and the largest step.
void CheckBaseline(const MeasuredProblem& p, const MeasuredFit& base, DiagnosisWithoutNetwork& dx) {
  std::vector<double> pooled;
  for (int u : p.Scored()) {
    const Eigen::VectorXd& e = base.held_residuals[static_cast<size_t>(u)];
    pooled.insert(pooled.end(), e.data(), e.data() + e.size());
    const MeasuredUnit& unit = p.units[static_cast<size_t>(u)];
    std::vector<double> t;
    for (size_t k : unit.blocks) t.push_back(p.block_times[static_cast<size_t>(unit.run)][k]);
    const auto step = LargestStep(e, t, unit.prepared.label);
    if (step && step->statistic > step->threshold) {
      dx.detected_steps.push_back(*step);
      dx.notes.push_back(StepNote(*step));
    }
  }
  dx.ljung_box_p["bias_dph"] = LjungBoxP(pooled, 10);
}

/// Score-block means of the scored units' held-out residuals, pooled.
std::vector<double> PooledScoreBlocks(const MeasuredProblem& p, const MeasuredFit& fit) {
  std::vector<double> out;
  for (int u : p.Scored()) {
    const auto s = UnitScoreBlocks(p, fit.held_residuals[static_cast<size_t>(u)], u);
    out.insert(out.end(), s.begin(), s.end());
  }
  return out;
}

/// The model's columns after the search, and the first search's candidates' columns.
struct Searched {
  std::vector<RunColumns> model, first;
};

/// Stages 5 and 6 repeated: each step scores every candidate not taken, ranks them by score and
/// accepts the leader when significant; its column joins the model's.
Searched SearchAndAccept(const MeasuredProblem& p, const std::vector<MeasuredCandidate>& candidates,
                         std::vector<RunColumns> model, const RankingRule& rule, DiagnosisWithoutNetwork& dx) {
  Searched out;
  std::set<CauseTarget> taken;
  MeasuredFit current = FitColumns(p, model, p.bias);
  for (int step = 0; step < p.options.max_steps; ++step) {
    Progress(p.options.progress)(fmt::format("step {}: scoring {} candidates", step + 1, candidates.size()));
    std::vector<MeasuredScored> scored = ScoreMeasured(p, model, candidates, taken, p.bias);
    std::vector<Candidate> all;
    for (const auto& s : scored) all.push_back(s.candidate);
    const std::vector<size_t> order = Rank(all, rule);
    std::vector<Candidate> ranked;
    for (size_t i : order) ranked.push_back(all[i]);
    if (step == 0) {
      dx.first_candidates = ranked;
      dx.first_significant = CountSignificant(ranked, rule);
      for (const auto& sc : scored) out.first.push_back(sc.column);
    }
    if (ranked.empty() || !Significant(ranked.front(), rule)) break;
    DiagnosisStep st;
    st.accepted = ranked.front();
    st.threshold = rule.bias_threshold;
    st.candidates = ranked;
    st.before.bias_rms_dph = current.held_out.rms();
    st.ties = Ties(ranked, rule);
    st.notes = TieNotes(ranked.front(), st.ties, false, rule.tie_score);
    model.push_back(std::move(scored[order.front()].column));
    const MeasuredFit after = FitColumns(p, model, p.bias);
    st.after.bias_rms_dph = after.held_out.rms();
    st.compensated_stability_ratio =
        sim::StdDev(PooledScoreBlocks(p, current)) / std::max(sim::StdDev(PooledScoreBlocks(p, after)), 1e-12);
    taken.insert({st.accepted.cause, st.accepted.target});
    dx.steps.push_back(std::move(st));
    current = after;
  }
  dx.extended.bias_rms_dph = current.held_out.rms();
  out.model = std::move(model);
  return out;
}

/// Per unit, the block means of the channels and the bias and, for scored units, the baseline's
/// and the final model's held-out bias residuals (the report's residuals.csv and figures).
std::vector<ResidualTrace> Traces(const MeasuredProblem& p, const MeasuredFit& base, const MeasuredFit& final_fit) {
  std::vector<ResidualTrace> out;
  const auto scored = p.Scored();
  for (size_t u = 0; u < p.units.size(); ++u) {
    const MeasuredUnit& unit = p.units[u];
    const auto r = static_cast<size_t>(unit.run);
    ResidualTrace tr;
    tr.run = unit.prepared.run->id;
    for (size_t k : unit.blocks) tr.t_s.push_back(p.block_times[r][k]);
    for (size_t c = 0; c < p.channels.size(); ++c)
      for (size_t k : unit.blocks) tr.measured[p.channels[c]].push_back(p.T[r](static_cast<Eigen::Index>(c), static_cast<Eigen::Index>(k)));
    for (size_t k : unit.blocks) tr.measured["bias_dph"].push_back(p.bias[r][static_cast<Eigen::Index>(k)]);
    if (std::find(scored.begin(), scored.end(), static_cast<int>(u)) != scored.end()) {
      const Eigen::VectorXd &b = base.held_residuals[u], &e = final_fit.held_residuals[u];
      tr.baseline["bias_dph"].assign(b.data(), b.data() + b.size());
      tr.extended["bias_dph"].assign(e.data(), e.data() + e.size());
    }
    out.push_back(std::move(tr));
  }
  return out;
}

DiagnosisWithoutNetwork RunStages(const MeasuredProblem& p) {
  DiagnosisWithoutNetwork dx = Header(p);
  const Progress progress(p.options.progress);
  progress("choosing the baseline polynomial");
  const PolynomialBaseline baseline = ChooseBaseline(p);  // stage 2
  dx.polynomial_order = baseline.spec.order;
  dx.polynomial_channel = baseline.spec.channel;
  dx.notes.push_back(BaselineNote(baseline));
  const MeasuredFit base = FitColumns(p, baseline.columns, p.bias);
  dx.baseline.bias_rms_dph = base.held_out.rms();
  CheckBaseline(p, base, dx);  // stage 3
  const std::vector<MeasuredCandidate> candidates = MeasuredCandidates(p, baseline.spec);
  MeasuredNull null;  // its threshold: min_score without replicates
  null.bootstrap.threshold = p.options.min_score;
  if (p.options.null_replicates > 0) {
    null = NullFromResiduals(p, baseline.columns, candidates);
    dx.notes.push_back(MeasuredNullNote(p, null));
  }
  dx.null_bootstrap = null.bootstrap;
  // Ranked by score alone: the catalog's plausible ranges are a ring laser gyro's, and without a
  // gyro file the data may be any gyro's.
  const RankingRule rule = RankingRule::WithoutNetwork(p.options, null.bootstrap.threshold);
  const Searched searched = SearchAndAccept(p, candidates, baseline.columns, rule, dx);
  progress("residuals for the report");  // stage 7
  std::vector<RunColumns> full = baseline.columns;
  full.insert(full.end(), searched.first.begin(), searched.first.end());
  const MeasuredUnexplained left = FindMeasuredUnexplained(p, searched.model, full, p.options.unexplained);
  dx.unexplained = left.entries;
  dx.bias_left = BiasLeft{left.rms_dph, left.noise_dph, left.data_covariate, left.data_r, left.null_correlation,
                          left.replicates};
  if (p.options.null_replicates > 0) {
    dx.notes.push_back(fmt::format("unexplained only where the final residual moves with {0}, d{0}/dt or heating and "
                                   "cooling more than on all of {1} null replicates (AR noise of the residuals of the "
                                   "baseline with every candidate at once): largest |r| {2:.2f} on the data, {3:.2f} on "
                                   "the replicates",
                                   p.channel, left.replicates, left.data_correlation, left.null_correlation));
  }
  dx.residuals = Traces(p, base, FitColumns(p, searched.model, p.bias));
  return dx;
}

}  // namespace

DiagnosisWithoutNetwork DiagnoseWithoutNetwork(const sim::Trace& data, const DiagnoseOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("diagnose: " + why);
  return RunStages(MakeMeasuredProblem(data, options));
}

}  // namespace rlg::diagnosis
