// The run of the diagnosis's stages (Engine::Run), the interface of model/diagnose.h, and
// DiagnoseOptions::IsValid.

#include "diagnosis/diagnose.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <set>

#include "diagnosis/engine.h"
#include "diagnosis/rank.h"
#include "diagnosis/report.h"
#include "diagnosis/score.h"
#include "sim/effect_registry.h"
#include "sim/errors.h"
#include "sim/stats.h"

namespace rlg::diagnosis {
std::vector<Candidate> Engine::FirstThermalCandidates(const Calibration& cal) const {
  const std::vector<int> all = All();
  const auto pred = SimulateAll(cal.model, all);
  std::vector<Model> models;
  return ThermalCandidates(cal.model, pred, ThermalChi2(ThermalResiduals(pred, all), fit_, cal.channel_var), cal.channel_var,
                           &models);
}

std::vector<Candidate> Engine::FirstBiasCandidates(const Calibration& cal) const {
  if (!has_bias_) return {};
  std::vector<std::vector<Extra>> extras;
  return BiasCandidates(cal.model, SimulateAll(cal.model, All()), {}, {}, nullptr, &extras);
}

Diagnosis Engine::Run() {
  Diagnosis dx;
  dx.has_bias = has_bias_;
  dx.score_block_s = {std::numeric_limits<double>::infinity(), 0.0};
  for (const auto& p : runs_) {
    dx.score_block_s.first = std::min(dx.score_block_s.first, p.score_block_s());
    dx.score_block_s.second = std::max(dx.score_block_s.second, p.score_block_s());
  }
  if (!split_note_.empty()) dx.notes.push_back(split_note_);
  const std::vector<int> all = All();

  // 1. Calibrate the nominal thermal network (stage 3; its channel variances weigh every
  //    thermal fit and score from here on).
  Progress("calibrating the nominal gyro");
  const Calibration cal = Calibrate();
  model_ = cal.model;
  const std::vector<double>& channel_var = cal.channel_var;
  dx.calibration = cal.summary;
  {
    // Identifiability: which combinations of the knobs the data determine, and which are
    // left to the prior.
    // Names and values come from the calibration's summary, the one record of the knobs.
    std::vector<std::string> names;
    for (const auto& knob : cal.summary.knobs) {
      names.push_back(knob.name);
      dx.calibrated[knob.name] = knob.calibrated;
    }
    dx.identifiability = diagnosis::AnalyseIdentifiability(cal.summary.covariance, names, cal.summary.prior_sd);
    if (names.size() >= 2) {
      dx.knob_correlations = diagnosis::CorrelationsGivenScale(cal.summary.covariance);
      dx.knob_names = names;
    }
    for (size_t r = 0; r < runs_.size(); ++r)
      if (!runs_[r].ambient_known && runs_[r].nuisance == static_cast<int>(r))
        dx.calibrated["T_amb:" + runs_[r].run->id] = model_.ambient[r];
  }
  dx.baseline = Measure(model_);
  // Whiteness of the baseline residuals.
  {
    const auto pred = SimulateAll(model_, all);
    const auto res = ThermalResiduals(pred, all);
    for (size_t s = 0; s < nominal_.sensors.size(); ++s) {
      std::vector<double> pooled;
      for (int r : all)
        if (s < res[r].size()) pooled.insert(pooled.end(), res[r][s].begin(), res[r][s].end());
      if (!pooled.empty()) dx.ljung_box_p[nominal_.sensors[s].channel] = diagnosis::LjungBoxP(pooled, 10);
    }
    if (has_bias_) {
      const auto held = HeldOutBias(Design(model_, pred, {}));
      std::vector<double> pooled;
      for (int r : Scored()) pooled.insert(pooled.end(), held[r].data(), held[r].data() + held[r].size());
      dx.ljung_box_p["bias_dph"] = diagnosis::LjungBoxP(pooled, 10);
      // Steps (diagnosis::LargestStep), reported where they pass the threshold.
      for (int r : Scored()) {
        const auto step = diagnosis::LargestStep(held[r], block_times_[r], runs_[r].label);
        if (step && step->statistic > step->threshold) {
          dx.detected_steps.push_back(*step);
          dx.notes.push_back(diagnosis::StepNote(*step));
        }
      }
    }
  }
  Model baseline_model = model_;
  std::vector<std::function<double(const Prediction&, size_t, int)>> accepted_extra;

  // 3. Search, accept, repeat.
  dx.null_bootstrap.threshold = o_.min_score;
  if (has_bias_ && o_.null_replicates > 0) {
    Progress(fmt::format("null bootstrap: {} replicates", o_.null_replicates));
    dx.null_bootstrap = NullBiasThreshold(SimulateAll(model_, all));
    dx.notes.push_back(NullBootstrapNote(dx.null_bootstrap));
  }
  const double bias_threshold = dx.null_bootstrap.threshold;
  for (int step = 0; step < o_.max_steps; ++step) {
    step_prefix_ = fmt::format("step {}: ", step + 1);
    const auto pred = SimulateAll(model_, all);
    const double chi2 = ThermalChi2(ThermalResiduals(pred, all), fit_, channel_var);
    std::vector<Model> models;
    NullBootstrap thermal_null;
    std::vector<Candidate> cands = ThermalCandidates(model_, pred, chi2, channel_var, &models, &thermal_null);
    if (step == 0) {
      dx.thermal_null_bootstrap = thermal_null;
      if (thermal_null.replicates > 0) dx.notes.push_back(ThermalNullNote(thermal_null));
    }
    std::vector<std::vector<std::function<double(const Prediction&, size_t, int)>>> extras(cands.size());
    if (has_bias_) {
      std::vector<std::vector<Extra>> bias_extras;
      std::set<std::string> taken;
      for (const auto& st : dx.steps) taken.insert(st.accepted.cause + "|" + CanonicalTarget(nominal_, st.accepted.cause, st.accepted.target));
      Progress("bias candidates");
      auto b = BiasCandidates(model_, pred, accepted_extra, taken, nullptr, &bias_extras);
      cands.insert(cands.end(), b.begin(), b.end());
      models.resize(cands.size(), model_);
      extras.insert(extras.end(), bias_extras.begin(), bias_extras.end());
    }
    // Stage 5: thermal causes are upstream, so a significant one is taken before any bias
    // candidate; exact twins by held-out RMS, then plausibility (diagnosis::Rank).
    const diagnosis::RankingRule rule = diagnosis::RankingRule::From(o_, thermal_null.threshold, bias_threshold);
    const std::vector<size_t> order = diagnosis::Rank(cands, rule);
    std::vector<Candidate> ranked;
    for (size_t i : order) ranked.push_back(cands[i]);
    if (step == 0) dx.first_candidates = ranked;
    if (ranked.empty() || !diagnosis::Significant(ranked.front(), rule)) break;
    const size_t best = order.front();
    DiagnosisStep st;
    st.accepted = cands[best];
    st.threshold = st.accepted.kind == "thermal" ? rule.thermal_threshold : rule.bias_threshold;
    st.candidates = ranked;
    st.before = Measure(model_);
    st.ties = diagnosis::Ties(ranked, rule);
    for (auto& n : diagnosis::TieNotes(ranked.front(), st.ties, has_logged_ambient_)) st.notes.push_back(std::move(n));
    if (st.accepted.kind == "thermal") {
      const Model previous = model_;
      model_ = models[best];
      // Recalibrate the whole network with the new element.
      const sim::Effect& effect = sim::RequireEffect(st.accepted.cause);
      std::vector<Free> free = BaselineFree(fit_);
      for (const auto& [k, v] : effect.Reported(model_.effects.back().parameters))
        free.push_back({Free::kEffect, static_cast<int>(model_.effects.size()) - 1, k, effect.FindParameter(k)->positive});
      if (!FitThermal(model_, free, fit_, channel_var, o_.calibration.max_iterations).usable)
        st.notes.push_back("the recalibration with " + st.accepted.cause + " " + st.accepted.target +
                           " could not start; the candidate's own refit stands");
      FitThermal(model_, AmbientFree(held_), held_, channel_var, o_.calibration.nuisance_max_iterations);
      st.accepted.parameters = effect.Reported(model_.effects.back().parameters);
      st.after = Measure(model_);
      for (size_t i = 0; i < knobs_.size(); ++i) {
        const double b = KnobShiftSigma(previous, i), a = KnobShiftSigma(model_, i);
        if (std::abs(a - b) >= 1.0 || std::max(std::abs(a), std::abs(b)) > kPriorConflictSigma)
          st.knob_shifts.push_back({knobs_[i].name, b, a});
      }
    } else {
      if (!st.accepted.shape_note.empty()) st.notes.push_back(st.accepted.shape_note);
      // Bias effects enter the simulation model as effects with the fitted parameters.
      const sim::EffectSpec e{st.accepted.cause, st.accepted.target,
                              sim::RequireEffect(st.accepted.cause).FromReported(st.accepted.parameters)};
      // Residual gain with the matching regressor in the compensation model.
      const BiasDesign before = Design(model_, pred, accepted_extra);
      auto extra = accepted_extra;
      extra.insert(extra.end(), extras[best].begin(), extras[best].end());
      const BiasDesign after = Design(model_, pred, extra);
      const auto hb = HeldOutBias(before), ha = HeldOutBias(after);
      std::vector<double> sb, sa;
      for (int r : Scored()) {
        const auto x = ToScoreBlocks(hb[r], r), y = ToScoreBlocks(ha[r], r);
        sb.insert(sb.end(), x.begin(), x.end());
        sa.insert(sa.end(), y.begin(), y.end());
      }
      st.compensated_stability_ratio = sim::StdDev(sb) / std::max(sim::StdDev(sa), 1e-12);
      st.after = st.before;
      st.after.bias_rms_dph = ScoreBias(ha).rms();
      accepted_extra = extra;
      model_.effects.push_back(e);
    }
    dx.steps.push_back(st);
  }
  step_prefix_.clear();
  Progress("residuals for the report");
  dx.extended = dx.steps.empty() ? dx.baseline : dx.steps.back().after;
  if (!dx.steps.empty() && has_bias_) {
    // Final bias RMS with every accepted bias regressor.
    const auto pred = SimulateAll(model_, all);
    dx.extended.bias_rms_dph = ScoreBias(HeldOutBias(Design(model_, pred, accepted_extra))).rms();
  }
  dx.extended_gyro = Build(nominal_, knobs_, model_);

  // Residual traces (fit-block resolution) for the report.
  const auto pb = SimulateAll(baseline_model, all), pe = SimulateAll(model_, all);
  const auto rb = ThermalResiduals(pb, all), re = ThermalResiduals(pe, all);
  std::vector<Eigen::VectorXd> bb, be;
  if (has_bias_) {
    bb = HeldOutBias(Design(baseline_model, pb, {}));
    be = HeldOutBias(Design(model_, pe, accepted_extra));
  }
  std::vector<diagnosis::ChannelResidual> channel_residuals;
  for (int r : all) {
    ResidualTrace tr;
    tr.run = runs_[r].run->id;
    tr.t_s = block_times_[r];
    auto block_means = [&](int col) {
      const Eigen::VectorXd m = BlockMeans(runs_[r].run->columns[col], r);
      return std::vector<double>(m.data(), m.data() + m.size());
    };
    auto negated = [](std::vector<double> v) {  // ThermalResiduals are simulated - measured
      for (double& x : v) x = -x;
      return v;
    };
    for (size_t s = 0; s < nominal_.sensors.size(); ++s) {
      if (runs_[r].sensor_col[s] < 0) continue;
      const std::string& ch = nominal_.sensors[s].channel;
      tr.measured[ch] = block_means(runs_[r].sensor_col[s]);
      tr.baseline[ch] = negated(rb[r][s]);
      tr.extended[ch] = negated(re[r][s]);
    }
    // Stage 6 inputs (diagnosis_unexplained.h): each channel's final residual, its noise, and
    // what it might move with.
    const sim::Run& run = *runs_[r].run;
    const double per_score_block = std::round(runs_[r].score_block_s() / runs_[r].sample_period_s);
    for (size_t s = 0; s < nominal_.sensors.size(); ++s) {
      const int col = runs_[r].sensor_col[s];
      if (col < 0) continue;
      diagnosis::ChannelResidual c;
      c.run = runs_[r].label;
      c.channel = nominal_.sensors[s].channel;
      c.t_s = tr.t_s;
      c.residual = tr.extended[c.channel];
      c.covariates[c.channel] = tr.measured[c.channel];
      c.covariates["d" + c.channel + "/dt"] = RatePerMinute(tr.t_s, tr.measured[c.channel]);
      for (size_t k = 0; k < run.columns.size(); ++k)
        if (run.names[k] == "T_amb" || run.names[k].rfind("P_", 0) == 0) c.covariates[run.names[k]] = block_means(static_cast<int>(k));
      // White noise from fourth differences (WhiteNoiseSd): a ramp's first differences are its
      // slope, 0.17 °C a sample at 1 °C/min and 10 s, which made every channel look quiet.
      c.score_block_noise = diagnosis::WhiteNoiseSd(run.columns[static_cast<size_t>(col)]) / std::sqrt(per_score_block);
      c.fit_blocks_per_score = runs_[r].fit_blocks_per_score;
      channel_residuals.push_back(std::move(c));
    }
    if (has_bias_ && bb[r].size() > 0) {
      tr.measured["bias_dph"] = block_means(runs_[r].bias_col);
      tr.baseline["bias_dph"] = std::vector<double>(bb[r].data(), bb[r].data() + bb[r].size());
      tr.extended["bias_dph"] = std::vector<double>(be[r].data(), be[r].data() + be[r].size());
    }
    dx.residuals.push_back(std::move(tr));
  }
  dx.unexplained = diagnosis::FindUnexplained(channel_residuals, o_.unexplained);
  return dx;
}

std::string CanonicalTarget(const sim::GyroConfig& g, const std::string& effect, const std::string& target) {
  const sim::Effect* e = sim::FindEffect(effect);
  return e ? e->CanonicalTarget(g, target) : sim::CanonicalNodeTarget(g, target);
}

bool DiagnoseOptions::IsValid(std::string* error) const {
  std::string why;
  if (max_steps < 0) why = fmt::format("max_steps must be 0 or more (got {})", max_steps);
  else if (single_run_pieces < 2) why = fmt::format("single_run_pieces must be at least 2 (got {})", single_run_pieces);
  else if (!(fit_block_s > 0.0 && std::isfinite(fit_block_s)))
    why = fmt::format("fit_block_s must be a positive number of seconds (got {:g})", fit_block_s);
  else if (!(score_block_s >= fit_block_s && std::isfinite(score_block_s)))
    why = fmt::format("score_block_s must be at least fit_block_s = {:g} s (got {:g})", fit_block_s, score_block_s);
  else if (!(min_heldout_ratio >= 1.0) || !(min_heldout_ratio_thermal >= 1.0))
    why = fmt::format("min_heldout_ratio and min_heldout_ratio_thermal must be at least 1 (got {:g}, {:g})",
                      min_heldout_ratio, min_heldout_ratio_thermal);
  else if (!(min_score >= 0.0) || !(tie_score >= 0.0))
    why = fmt::format("min_score and tie_score must be 0 or more (got {:g}, {:g})", min_score, tie_score);
  else if (null_replicates < 0 || thermal_refits < 0)
    why = fmt::format("null_replicates and thermal_refits must be 0 or more (got {}, {})", null_replicates, thermal_refits);
  else if (calibration.IsValid(&why))
    unexplained.IsValid(&why);
  if (error) *error = why;
  return why.empty();
}

Diagnosis Diagnose(const sim::Trace& data, const sim::GyroConfig& nominal, const DiagnoseOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("diagnose: " + why);
  diagnosis::Engine engine(data, nominal, options);
  return engine.Run();
}

CalibrationSummary Calibrate(const sim::Trace& data, const sim::GyroConfig& nominal, const DiagnoseOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw InputError("diagnose: " + why);
  const diagnosis::Engine engine(data, nominal, options);
  return engine.Calibrate().summary;
}

}  // namespace rlg::diagnosis
