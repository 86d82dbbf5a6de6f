// Diagnose: the stages in order (diagnose.h), each a function of the problem and the model it
// is given; the current model is a local of RunStages.

#include "diagnosis/diagnose.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <limits>
#include <optional>
#include <set>
#include <stdexcept>

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
  ThermalSearch thermal;  // the thermal search as made, for the next step after a bias cause (Rebased)
};

/// `search`, the thermal search of model `searched`, as that of m: `searched` with the bias
/// causes since accepted (AcceptBias appends their effects and changes nothing else). The
/// thermal simulation reads no bias term, so searching m again would repeat every screen, fit
/// and score to the bit (on a bias cause's data ~40 % of a diagnosis); only the models it
/// leaves differ, each refitted one holding m's effects before its candidate's.
ThermalSearch Rebased(ThermalSearch search, const Model& searched, const Model& m) {
  for (Model& model : search.models) {
    // Every refitted model extends the searched one (its effects first, the candidate's after).
    if (model.effects.size() < searched.effects.size()) {
      throw std::logic_error("Rebased: a model that does not extend its search's");
    }
    std::vector<sim::EffectSpec> effects = m.effects;
    effects.insert(effects.end(), model.effects.begin() + static_cast<std::ptrdiff_t>(searched.effects.size()),
                   model.effects.end());
    model.effects = std::move(effects);
  }
  return search;
}

/// The search step of model m. `thermal`: m's thermal search where it is known (Rebased),
/// else it is searched.
StepSearch SearchStep(const Problem& p, const Model& m, const std::vector<Prediction>& pred,
                      const std::vector<double>& channel_var, const std::vector<Extra>& bias_columns,
                      const std::vector<DiagnosisStep>& steps, const Progress& progress,
                      std::optional<ThermalSearch> thermal = std::nullopt) {
  if (thermal) {
    progress(fmt::format("thermal candidates: the last step's {} (a bias cause since changes none of them)",
                         thermal->candidates.size()));
  } else {
    thermal = SearchThermal(p, m, pred, channel_var, true, progress);
  }
  StepSearch out{thermal->candidates, thermal->models, {}, {}, thermal->null, std::move(*thermal)};
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

/// What looking one step ahead decided (CompareAhead): the contender taken (its place in the
/// ranking; 0 the leader), its acceptance and the next step's search after it (both unset
/// where there was nothing to compare), and a note where contenders were compared.
struct LookAhead {
  size_t chosen = 0;
  std::optional<Accepted> accepted;
  std::optional<StepSearch> next;
  std::vector<std::string> notes;
};

/// Thermal candidates that tie the leader of step `step` (0-based) in score (within kTieBand;
/// significant; fitted inside the catalog's range where the leader is; an exact twin of one
/// already taken, its score within rule.tie_score, is the same prediction and not compared
/// again) are compared one step ahead, up to options.lookahead of them, the leader first: each
/// is accepted (AcceptThermal, `st` its record so far: a recalibration) and the next step
/// searched from the model it leaves, null bootstrap and all. Each is worth its score plus the
/// score of the candidate the next step would accept where that is thermal (0 where it is a
/// bias candidate, scored on other data, or nothing is significant). The most worth is taken;
/// the leader unless a rival is worth more. A tie in score is a coin toss the machine's
/// rounding can turn (refgen's missing link and missing mass at 1 s: sensor lag led the link
/// by 0.2 points, and after it the link was never found); the two steps are not. Nothing to
/// compare (a bias leader, no tie in score): nothing is done, and the step is accepted as
/// ranked.
LookAhead CompareAhead(const Problem& p, int step, const Model& model, const std::vector<double>& channel_var,
                       const std::vector<Extra>& bias_columns, const Diagnosis& dx, const StepSearch& search,
                       const std::vector<Candidate>& ranked, const std::vector<size_t>& order,
                       const RankingRule& rule, const DiagnosisStep& st) {
  LookAhead out;
  const Candidate& lead = ranked.front();
  if (lead.kind != CandidateKind::kThermal) return out;
  const bool lead_plausible = PlausibleFit(lead);
  std::vector<size_t> contenders = {0};  // places in the ranking
  for (size_t i = 1; i < ranked.size() && contenders.size() < static_cast<size_t>(p.options.lookahead); ++i) {
    const Candidate& c = ranked[i];
    const bool twin = std::any_of(contenders.begin(), contenders.end(),
                                  [&](size_t k) { return std::abs(ranked[k].score - c.score) < rule.tie_score; });
    if (c.kind == CandidateKind::kThermal && Significant(c, rule) && std::abs(c.score - lead.score) < kTieBand &&
        (PlausibleFit(c) || !lead_plausible) && !twin)
      contenders.push_back(i);
  }
  if (contenders.size() < 2) return out;
  struct Path {
    Accepted accepted;
    StepSearch next;
    double worth;
    std::string then;  // the next step's leader, or "nothing significant"
  };
  std::vector<Path> paths;
  for (size_t i : contenders) {
    DiagnosisStep trial = st;
    trial.accepted = ranked[i];
    const Progress progress(p.options.progress, fmt::format("step {} (ahead, after {} {}): ", step + 2,
                                                            trial.accepted.cause, trial.accepted.target));
    progress("recalibrating");
    Accepted a = AcceptThermal(p, model, search.models[order[i]], channel_var, bias_columns, std::move(trial));
    std::vector<DiagnosisStep> steps = dx.steps;
    steps.push_back(a.step);
    const auto pred = SimulateAll(p, a.model, p.All());
    StepSearch next = SearchStep(p, a.model, pred, channel_var, a.bias_columns, steps, progress);
    const RankingRule next_rule = RankingRule::WithNetwork(p.options, next.thermal_null.threshold, rule.bias_threshold);
    const std::vector<size_t> next_order = Rank(next.candidates, next_rule);
    double worth = ranked[i].score;
    std::string then = "nothing significant";
    if (!next_order.empty() && Significant(next.candidates[next_order.front()], next_rule)) {
      const Candidate& n = next.candidates[next_order.front()];
      if (n.kind == CandidateKind::kThermal) worth += n.score;
      then = fmt::format("{} {} ({:.1f}{})", n.cause, n.target, n.score,
                         n.kind == CandidateKind::kThermal ? "" : ", bias: not counted");
    }
    paths.push_back({std::move(a), std::move(next), worth, std::move(then)});
  }
  size_t pick = 0;
  for (size_t k = 1; k < paths.size(); ++k)
    if (paths[k].worth > paths[pick].worth) pick = k;
  std::vector<std::string> items;
  for (size_t k = 0; k < paths.size(); ++k)
    items.push_back(fmt::format("{} {} ({:.1f}) then {}: {:.1f}", ranked[contenders[k]].cause,
                                ranked[contenders[k]].target, ranked[contenders[k]].score, paths[k].then,
                                paths[k].worth));
  bool close = false;
  for (size_t k = 0; k < paths.size(); ++k)
    if (k != pick && paths[pick].worth - paths[k].worth < kTieBand) close = true;
  out.notes.push_back(fmt::format("looked one step ahead (a tie in score): {}; taken: the most worth in two steps{}",
                                  fmt::join(items, "; "),
                                  close ? ", by less than the tie band (the two steps do not tell them apart either)" : ""));
  out.chosen = contenders[pick];
  out.accepted = std::move(paths[pick].accepted);
  out.next = std::move(paths[pick].next);
  return out;
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
  // A lookahead's search of the model the next step starts from (LookAhead), used by that step;
  // after a bias cause, the thermal search of the model it extended (Rebased).
  std::optional<StepSearch> searched;
  std::optional<ThermalSearch> thermal_searched;
  for (int step = 0; step < p.options.max_steps; ++step) {
    const auto pred = SimulateAll(p, model, p.All());
    const Progress step_progress(p.options.progress, fmt::format("step {}: ", step + 1));
    StepSearch search = searched ? std::move(*searched)
                                 : SearchStep(p, model, pred, cal.channel_var, bias_columns, dx.steps, step_progress,
                                              std::move(thermal_searched));
    searched.reset();
    thermal_searched.reset();
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
    std::vector<size_t> order = Rank(search.candidates, rule);
    std::vector<Candidate> ranked;
    for (size_t i : order) ranked.push_back(search.candidates[i]);
    if (step == 0) {
      dx.first_candidates = ranked;
      dx.first_significant = CountSignificant(ranked, rule);
    }
    if (ranked.empty() || !Significant(ranked.front(), rule)) break;
    DiagnosisStep st;
    st.threshold = ranked.front().kind == CandidateKind::kThermal ? rule.thermal_threshold : rule.bias_threshold;
    st.before = Measure(p, model);
    std::optional<Accepted> accepted;
    std::vector<std::string> lookahead_notes;
    if (step + 1 < p.options.max_steps) {
      LookAhead ahead = CompareAhead(p, step, model, cal.channel_var, bias_columns, dx, search, ranked, order, rule, st);
      if (ahead.chosen > 0) {  // the contender ranked `chosen` leads the step
        std::rotate(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(ahead.chosen),
                    order.begin() + static_cast<std::ptrdiff_t>(ahead.chosen) + 1);
        std::rotate(ranked.begin(), ranked.begin() + static_cast<std::ptrdiff_t>(ahead.chosen),
                    ranked.begin() + static_cast<std::ptrdiff_t>(ahead.chosen) + 1);
      }
      accepted = std::move(ahead.accepted);
      searched = std::move(ahead.next);
      lookahead_notes = std::move(ahead.notes);
    }
    const size_t best = order.front();
    st.accepted = search.candidates[best];
    st.candidates = ranked;
    st.ties = Ties(ranked, rule, TieScoreDifferences(p, model, pred, bias_columns, search, order, rule));
    st.notes = TieNotes(ranked.front(), st.ties, p.has_logged_ambient, rule.tie_score);
    st.notes.insert(st.notes.end(), lookahead_notes.begin(), lookahead_notes.end());
    if (accepted) {  // accepted by the lookahead: its record with this step's ranking, ties and notes
      DiagnosisStep& done = accepted->step;
      done.candidates = std::move(st.candidates);
      done.ties = std::move(st.ties);
      done.notes.insert(done.notes.begin(), st.notes.begin(), st.notes.end());
    } else {
      accepted = st.accepted.kind == CandidateKind::kThermal
                     ? AcceptThermal(p, model, search.models[best], cal.channel_var, bias_columns, std::move(st))
                     : AcceptBias(p, model, pred, bias_columns, search.columns[best], std::move(st));
    }
    if (accepted->step.accepted.kind == CandidateKind::kBias)
      thermal_searched = Rebased(std::move(search.thermal), model, accepted->model);
    model = std::move(accepted->model);
    bias_columns = std::move(accepted->bias_columns);
    dx.steps.push_back(std::move(accepted->step));
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
