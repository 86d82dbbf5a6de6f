// Diagnose: the stages in order (diagnose.h), each a function of the problem and the model it
// is given; the current model is a local of RunStages.

#include "diagnosis/diagnose.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <set>

#include "diagnosis/catalog/effect_search.h"
#include "diagnosis/network/accept.h"
#include "diagnosis/network/bias_null.h"
#include "diagnosis/network/bias_search.h"
#include "diagnosis/network/calibrate.h"
#include "diagnosis/network/metrics.h"
#include "diagnosis/network/problem.h"
#include "diagnosis/progress.h"
#include "diagnosis/statistics/rank.h"
#include "diagnosis/network/residual_checks.h"
#include "diagnosis/network/thermal_null.h"
#include "diagnosis/network/thermal_residuals.h"
#include "diagnosis/network/thermal_search.h"
#include "diagnosis/network/traces.h"
#include "sim/effect_registry.h"
#include "sim/errors.h"

namespace rlg::diagnosis {

namespace {

/// What the record says of the problem before any fit: bias data, score-block lengths, the
/// split of a single run.
Diagnosis Header(const Problem& p) {
  Diagnosis dx;
  dx.has_bias = p.has_bias;
  dx.score_block_s = {std::numeric_limits<double>::infinity(), 0.0};
  for (const auto& run : p.runs) {
    dx.score_block_s.first = std::min(dx.score_block_s.first, run.score_block_s());
    dx.score_block_s.second = std::max(dx.score_block_s.second, run.score_block_s());
  }
  if (!p.split_note.empty()) dx.notes.push_back(p.split_note);
  return dx;
}

/// The calibration's record: its summary, the knobs' values, which combinations of them the
/// data determine and which are left to the prior (names and values from the summary, the one
/// record of the knobs), and the fitted ambient of a run that logs none.
void RecordCalibration(const Problem& p, const Calibration& cal, Diagnosis& dx) {
  dx.calibration = cal.summary;
  std::vector<std::string> names;
  std::vector<KnobLabel> labels;
  for (const auto& knob : cal.summary.knobs) {
    names.push_back(knob.name);
    labels.push_back(knob.label);
    dx.calibrated[knob.name] = knob.calibrated;
  }
  dx.identifiability = AnalyseIdentifiability(cal.summary.covariance, labels, cal.summary.prior_sd);
  if (names.size() >= 2) {
    dx.knob_correlations = CorrelationsGivenScale(cal.summary.covariance);
    dx.knob_names = names;
  }
  for (size_t r = 0; r < p.runs.size(); ++r)
    if (!p.runs[r].ambient_known && p.runs[r].nuisance == static_cast<int>(r))
      dx.calibrated["T_amb:" + p.runs[r].run->id] = cal.model.ambient[r];
}

/// The candidates of one search step: thermal (stage 4) then bias (stage 5), each with the
/// model it would leave (the searched one for bias) and its bias columns (none for thermal).
struct StepSearch {
  std::vector<Candidate> candidates;
  std::vector<Model> models;
  std::vector<std::vector<Extra>> columns;
  std::vector<int> counted;  // a bias candidate's parameters counted in its score (0 for thermal ones)
  NullBootstrap thermal_null;
};

StepSearch SearchStep(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                      const std::vector<double>& channel_var, const std::vector<Extra>& bias_columns,
                      const std::vector<DiagnosisStep>& steps, const Progress& progress) {
  ThermalSearch thermal = SearchThermal(p, m, pred, channel_var, true, progress);
  StepSearch out{std::move(thermal.candidates), std::move(thermal.models), {}, {}, std::move(thermal.null)};
  out.columns.resize(out.candidates.size());
  out.counted.resize(out.candidates.size(), 0);
  if (!p.has_bias) return out;
  std::set<CauseTarget> taken;
  for (const auto& st : steps)
    taken.insert({st.accepted.cause, CanonicalTarget(p.nominal, st.accepted.cause, st.accepted.target)});
  progress("bias candidates");
  BiasSearch bias = SearchBias(p, m, pred, bias_columns, taken);
  out.candidates.insert(out.candidates.end(), bias.candidates.begin(), bias.candidates.end());
  out.models.resize(out.candidates.size(), m);
  out.columns.insert(out.columns.end(), bias.extras.begin(), bias.extras.end());
  out.counted.insert(out.counted.end(), bias.counted.begin(), bias.counted.end());
  return out;
}

/// Per ranked candidate, its score less the leader's as the tie rule compares them: for a bias
/// leader, each significant bias candidate's under one noise model (PairedScores); NaN
/// elsewhere (the difference of the scores).
std::vector<double> TieScoreDifferences(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                                        const std::vector<Extra>& bias_columns, const StepSearch& search,
                                        const std::vector<size_t>& order, const RankingRule& rule) {
  std::vector<double> out(order.size(), std::nan(""));
  const size_t lead = order.front();
  if (search.candidates[lead].kind != CandidateKind::kBias) return out;
  const PairedScores paired(p, m, pred, bias_columns, search.columns[lead], search.counted[lead]);
  for (size_t i = 1; i < order.size(); ++i) {
    const Candidate& c = search.candidates[order[i]];
    if (c.kind != CandidateKind::kBias || !Significant(c, rule)) continue;
    out[i] = paired.Difference(search.columns[order[i]], search.counted[order[i]]);
  }
  return out;
}

/// The extended model's record: its metrics (with every accepted bias column), gyro, residual
/// traces and what it leaves unexplained (stage 7's inputs).
void RecordExtended(const Problem& p, const Model& baseline, const Model& model, const std::vector<Extra>& bias_columns,
                    Diagnosis& dx) {
  dx.extended = dx.steps.empty() ? dx.baseline : dx.steps.back().after;
  if (!dx.steps.empty() && p.has_bias) {
    const auto pred = SimulateAll(p, model, p.All());
    dx.extended.bias_rms_dph = ScoreBias(p, HeldOutBias(p, Design(p, model, pred, bias_columns))).rms();
  }
  dx.extended_gyro = Build(p.nominal, p.knobs, model);
  Traces traces = MakeTraces(p, baseline, model, bias_columns);
  dx.residuals = std::move(traces.residuals);
  dx.unexplained = FindUnexplained(traces.channel_residuals, p.options.unexplained);
}

Diagnosis RunStages(const Problem& p) {
  Diagnosis dx = Header(p);
  const Progress progress(p.options.progress);
  // Stage 2: the calibration; its channel variances weigh every thermal fit and score from here on.
  progress("calibrating the nominal gyro");
  const Calibration cal = Calibrate(p, NominalModel(p));
  RecordCalibration(p, cal, dx);
  dx.baseline = Measure(p, cal.model);
  ResidualChecks checks = CheckResiduals(p, cal.model);  // stage 3
  dx.ljung_box_p = std::move(checks.ljung_box_p);
  dx.detected_steps = std::move(checks.detected_steps);
  dx.notes.insert(dx.notes.end(), checks.notes.begin(), checks.notes.end());
  // Stages 4-6 on the current model, which each accepted step extends.
  Model model = cal.model;
  std::vector<Extra> bias_columns;
  dx.null_bootstrap.threshold = p.options.min_score;
  if (p.has_bias && p.options.null_replicates > 0) {
    progress(fmt::format("null bootstrap: {} replicates", p.options.null_replicates));
    dx.null_bootstrap = NullBiasThreshold(p, model, SimulateAll(p, model, p.All()));
    dx.notes.push_back(NullBootstrapNote(p, dx.null_bootstrap));
  }
  for (int step = 0; step < p.options.max_steps; ++step) {
    const auto pred = SimulateAll(p, model, p.All());
    const Progress step_progress(p.options.progress, fmt::format("step {}: ", step + 1));
    StepSearch search = SearchStep(p, model, pred, cal.channel_var, bias_columns, dx.steps, step_progress);
    if (step == 0) {
      dx.thermal_null_bootstrap = search.thermal_null;
      if (search.thermal_null.replicates > 0) dx.notes.push_back(ThermalNullNote(p, search.thermal_null));
      if (p.options.power) {
        progress("power of the thermal search");
        dx.power = ThermalPower(p, model, pred, cal.channel_var, search.thermal_null.threshold);
        if (p.has_bias) {
          progress("power of the bias search");
          for (auto& e : BiasPower(p, model, pred, dx.null_bootstrap.threshold)) dx.power.push_back(std::move(e));
        }
        for (auto& e : dx.power) {
          e.detected_plausible = PlausibleSize(e.cause, e.at, e.parameter, e.detected);
          e.named_plausible = PlausibleSize(e.cause, e.at, e.parameter, e.named);
        }
      }
    }
    // Stage 6: thermal causes are upstream, so a significant one is taken before any bias candidate;
    // exact twins by held-out gain, then plausibility (Rank).
    const RankingRule rule = RankingRule::WithNetwork(p.options, search.thermal_null.threshold, dx.null_bootstrap.threshold);
    const std::vector<size_t> order = Rank(search.candidates, rule);
    std::vector<Candidate> ranked;
    for (size_t i : order) ranked.push_back(search.candidates[i]);
    if (step == 0) dx.first_candidates = ranked;
    if (ranked.empty() || !Significant(ranked.front(), rule)) break;
    const size_t best = order.front();
    DiagnosisStep st;
    st.accepted = search.candidates[best];
    st.threshold = st.accepted.kind == CandidateKind::kThermal ? rule.thermal_threshold : rule.bias_threshold;
    st.candidates = ranked;
    st.before = Measure(p, model);
    st.ties = Ties(ranked, rule, TieScoreDifferences(p, model, pred, bias_columns, search, order, rule));
    for (auto& n : TieNotes(ranked.front(), st.ties, p.has_logged_ambient)) st.notes.push_back(std::move(n));
    Accepted accepted = st.accepted.kind == CandidateKind::kThermal
                            ? AcceptThermal(p, model, search.models[best], cal.channel_var, bias_columns, std::move(st))
                            : AcceptBias(p, model, pred, bias_columns, search.columns[best], std::move(st));
    model = std::move(accepted.model);
    bias_columns = std::move(accepted.bias_columns);
    dx.steps.push_back(std::move(accepted.step));
  }
  progress("residuals for the report");  // stage 7
  RecordExtended(p, cal.model, model, bias_columns, dx);
  return dx;
}

}  // namespace

std::string CanonicalTarget(const sim::GyroConfig& g, const std::string& effect, const std::string& target) {
  const sim::Effect* e = sim::FindEffect(effect);
  return e ? e->CanonicalTarget(g, target) : sim::CanonicalNodeTarget(g, target);
}

Diagnosis Diagnose(const sim::Trace& data, const sim::GyroConfig& nominal, const DiagnoseOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("diagnose: " + why);
  return RunStages(MakeProblem(data, nominal, options));
}

CalibrationSummary Calibrate(const sim::Trace& data, const sim::GyroConfig& nominal, const DiagnoseOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("diagnose: " + why);
  const Problem p = MakeProblem(data, nominal, options);
  return Calibrate(p, NominalModel(p)).summary;
}

}  // namespace rlg::diagnosis
