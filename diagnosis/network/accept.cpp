#include "diagnosis/network/accept.h"

#include <algorithm>
#include <cmath>

#include "diagnosis/network/calibration_summary.h"
#include "diagnosis/network/fit_thermal.h"
#include "diagnosis/network/free.h"
#include "diagnosis/network/knob_prior.h"
#include "diagnosis/network/metrics.h"
#include "diagnosis/catalog/effect_search.h"
#include "sim/stats.h"

namespace rlg::diagnosis {

Accepted AcceptThermal(const Problem& p, const Model& current, const Model& refitted,
                       const std::vector<double>& channel_var, const std::vector<Extra>& bias_columns,
                       DiagnosisStep step) {
  Accepted out{std::move(step), refitted, bias_columns};
  DiagnosisStep& st = out.step;
  // Recalibrate the whole network with the new element.
  const EffectSearch& effect = RequireSearch(st.accepted.cause);
  std::vector<Free> free = BaselineFree(p, p.fit);
  for (const auto& [k, v] : effect.Reported(out.model.effects.back().parameters))
    free.push_back({Free::kEffect, static_cast<int>(out.model.effects.size()) - 1, k, effect.effect().FindParameter(k)->positive});
  const ThermalFit fit = FitThermal(p, out.model, free, p.fit, channel_var, p.options.calibration.max_iterations);
  if (!fit.summary.usable)
    st.notes.push_back("the recalibration with " + st.accepted.cause + " " + st.accepted.target +
                       " could not start; the candidate's own refit stands");
  out.model = FitThermal(p, fit.model, AmbientFree(p, p.held), p.held, channel_var,
                         p.options.calibration.nuisance_max_iterations).model;
  st.accepted.parameters = effect.Reported(out.model.effects.back().parameters);
  st.after = Measure(p, out.model);
  for (size_t i = 0; i < p.knobs.size(); ++i) {
    const double b = KnobShiftSigma(p, current, i), a = KnobShiftSigma(p, out.model, i);
    if (std::abs(a - b) >= 1.0 || std::max(std::abs(a), std::abs(b)) > kPriorConflictSigma)
      st.knob_shifts.push_back({p.knobs[i].name, b, a});
  }
  return out;
}

Accepted AcceptBias(const Problem& p, const Model& current, const std::vector<Prediction>& pred,
                    const std::vector<Extra>& bias_columns, const std::vector<Extra>& columns, DiagnosisStep step) {
  Accepted out{std::move(step), current, bias_columns};
  DiagnosisStep& st = out.step;
  if (!st.accepted.shape_note.empty()) st.notes.push_back(st.accepted.shape_note);
  // Bias effects enter the simulation model as effects with the fitted parameters.
  const sim::EffectSpec e{st.accepted.cause, st.accepted.target,
                          RequireSearch(st.accepted.cause).FromReported(st.accepted.parameters)};
  // Residual gain with the matching regressor in the compensation model.
  const BiasDesign before = Design(p, current, pred, bias_columns);
  out.bias_columns.insert(out.bias_columns.end(), columns.begin(), columns.end());
  const BiasDesign after = Design(p, current, pred, out.bias_columns);
  const auto hb = HeldOutBias(p, before), ha = HeldOutBias(p, after);
  std::vector<double> sb, sa;
  for (int r : p.Scored()) {
    const auto x = ToScoreBlocks(p, hb[r], r), y = ToScoreBlocks(p, ha[r], r);
    sb.insert(sb.end(), x.begin(), x.end());
    sa.insert(sa.end(), y.begin(), y.end());
  }
  st.compensated_stability_ratio = sim::StdDev(sb) / std::max(sim::StdDev(sa), 1e-12);
  st.after = st.before;
  st.after.bias_rms_dph = ScoreBias(p, ha).rms();
  out.model.effects.push_back(e);
  return out;
}

}  // namespace rlg::diagnosis
