// The JSON of a diagnosis (report.h): every key docs/data-format.md lists.

#include "diagnosis/report.h"

#include <cmath>

#include "diagnosis/statistics/rank.h"

namespace rlg::diagnosis {

namespace {

nlohmann::json MetricsJson(const Metrics& m, bool bias) {
  nlohmann::json j;
  if (bias) j["bias_rms_dph"] = m.bias_rms_dph;
  j["temperature_rms_C"] = m.temperature_rms_C;
  return j;
}

nlohmann::json CandidateJson(const Candidate& c) {
  return {{"cause", c.cause}, {"target", c.target}, {"score", c.score}, {"heldout_rms_ratio", c.heldout_rms_ratio},
          {"heldout_gain", c.heldout_gain}, {"parameters", c.parameters}, {"kind", KindName(c.kind)}};
}

}  // namespace

nlohmann::json CalibrationJson(const CalibrationSummary& c) {
  nlohmann::json knobs = nlohmann::json::array();
  for (const auto& k : c.knobs) {
    knobs.push_back({{"name", k.name}, {"nominal", k.nominal}, {"calibrated", k.calibrated}, {"shift_sigma", k.shift_sigma},
                     {"posterior_sd", k.posterior_sd}});
  }
  nlohmann::json starts = nlohmann::json::array();
  for (const auto& s : c.starts) starts.push_back({{"run", s.run}, {"offset_C", s.offset_C}, {"prior_sd_C", s.prior_sd_C}});
  return {{"usable", c.usable},
          {"cost", {{"initial", c.initial_cost}, {"final", c.final_cost}}},
          {"iterations", c.iterations},
          {"start_capacity_scale", c.start_capacity_scale},
          {"prior_sd", c.prior_sd},
          {"knobs", knobs},
          {"starts", starts},
          {"prior_conflicts", c.PriorConflicts()},
          {"joint_shift", {{"chi2", c.JointShiftChi2()}, {"knobs", c.knobs.size()}, {"p", c.JointShiftP()},
                           {"conflict", c.JointConflict()}}}};
}

nlohmann::json IdentifiabilityJson(const Identifiability& id) {
  nlohmann::json undetermined = nlohmann::json::array();
  for (const auto& dir : id.undetermined) {
    nlohmann::json loadings = nlohmann::json::array();
    for (const auto& [knob, loading] : dir.loadings) loadings.push_back({{"knob", knob}, {"loading", loading}});
    undetermined.push_back({{"sd_ratio", dir.sd_ratio}, {"loadings", loadings}, {"reason", dir.reason}});
  }
  return {{"knobs", id.knobs}, {"determined", id.determined}, {"prior_sd", id.prior_sd}, {"undetermined", undetermined}};
}

namespace {

/// The JSON of either record: `network` set for a diagnosis against a gyro (without one its
/// keys are written empty, as an empty Diagnosis has them), `poly` without a network.
nlohmann::json Json(const SearchRecord& d, const Diagnosis* network, const DiagnosisWithoutNetwork* poly) {
  static const Diagnosis kNoNetwork;
  const Diagnosis& net = network != nullptr ? *network : kNoNetwork;
  nlohmann::json j;
  const bool none = d.steps.empty();
  j["cause"] = none ? "none" : d.steps.front().accepted.cause;
  j["target"] = none ? "" : d.steps.front().accepted.target;
  j["parameters"] = none ? nlohmann::json::object() : nlohmann::json(d.steps.front().accepted.parameters);
  // The causes these data do not tell from the first: its ambiguous ties (statistics/rank.h).
  j["ambiguous_with"] = nlohmann::json::array();
  if (!none)
    for (const Tie& t : d.steps.front().ties)
      if (t.ambiguous)
        j["ambiguous_with"].push_back({{"cause", t.cause},
                                       {"target", t.target},
                                       {"score_difference", t.score_difference},
                                       {"heldout_difference", t.heldout_difference}});
  j["baseline"] = MetricsJson(d.baseline, d.has_bias);
  j["extended"] = MetricsJson(none ? d.baseline : d.extended, d.has_bias);
  j["gain"] = {{"heldout_rms_ratio", HeadlineRmsRatio(d)}, {"compensated_stability_ratio", CompensatedStabilityRatio(d)}};
  j["candidates"] = nlohmann::json::array();
  for (const auto& c : d.first_candidates) j["candidates"].push_back(CandidateJson(c));
  j["accepted"] = nlohmann::json::array();
  for (const auto& s : d.steps) {
    nlohmann::json a = CandidateJson(s.accepted);
    a["threshold"] = s.threshold;
    a["compensated_stability_ratio"] = s.compensated_stability_ratio;
    a["before"] = MetricsJson(s.before, d.has_bias);
    a["after"] = MetricsJson(s.after, d.has_bias);
    a["notes"] = s.notes;
    a["ties"] = nlohmann::json::array();
    for (const auto& t : s.ties)
      a["ties"].push_back({{"cause", t.cause},
                           {"target", t.target},
                           {"score_difference", t.score_difference},
                           {"heldout_difference", t.heldout_difference},
                           {"ambiguous", t.ambiguous},
                           {"plausible", t.plausible}});
    a["knobs"] = nlohmann::json::array();
    for (const auto& k : s.knob_shifts)
      a["knobs"].push_back({{"name", k.name}, {"shift_sigma_before", k.before_sigma}, {"shift_sigma_after", k.after_sigma}});
    const auto outside = OutsidePlausibleRange(s.accepted);
    a["plausible"] = outside.empty();
    if (!outside.empty()) {
      nlohmann::json list = nlohmann::json::array();
      for (const auto& v : outside) {
        list.push_back({{"parameter", v.parameter->name}, {"value", v.value}, {"unit", v.parameter->unit},
                        {"plausible_range", {v.parameter->lo, v.parameter->hi}}, {"source", v.parameter->source}});
      }
      a["implausible"] = list;
    }
    j["accepted"].push_back(a);
  }
  j["calibrated"] = net.calibrated;
  j["calibration"] = CalibrationJson(net.calibration);
  j["identifiability"] = diagnosis::IdentifiabilityNotes(net.identifiability);
  j["identifiability_directions"] = IdentifiabilityJson(net.identifiability);
  j["detected_steps"] = nlohmann::json::array();
  for (const auto& st : d.detected_steps) {
    j["detected_steps"].push_back({{"run", st.run}, {"t_s", st.t_s}, {"size_dph", st.size}, {"statistic", st.statistic},
                                   {"threshold", st.threshold}});
  }
  nlohmann::json corr = nlohmann::json::object();
  for (size_t a = 0; a < net.knob_names.size(); ++a)
    for (size_t b = 0; b < net.knob_names.size(); ++b)
      corr[net.knob_names[a]][net.knob_names[b]] =
          net.knob_correlations(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
  j["parameter_correlations"] = corr;
  j["ljung_box_p"] = d.ljung_box_p;
  if (!net.power.empty()) {
    // A size no candidate reaches (infinite) is written as null.
    auto size = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
    j["power"] = {{"probability", kPowerLevel}, {"candidates", nlohmann::json::array()}};
    for (const auto& e : net.power) {
      j["power"]["candidates"].push_back({{"cause", e.cause},
                                          {"target", e.target},
                                          {"parameter", e.parameter},
                                          {"start", e.start},
                                          {"at", e.at},
                                          {"lambda_at_start", e.lambda_at_start},
                                          {"detected", size(e.detected)},
                                          {"named", size(e.named)},
                                          {"detected_plausible", e.detected_plausible},
                                          {"named_plausible", e.named_plausible},
                                          {"rival", e.rival_cause.empty() ? nlohmann::json(nullptr)
                                                                          : nlohmann::json{{"cause", e.rival_cause},
                                                                                           {"target", e.rival_target}}},
                                          {"rival_cosine", e.rival_cosine}});
    }
  }
  j["unexplained"] = nlohmann::json::array();
  for (const auto& u : d.unexplained) {
    j["unexplained"].push_back({{"channel", u.channel},
                                {"run", u.run},
                                {"rms_over_noise", u.rms_over_noise},
                                {"noise", u.noise},
                                {"ljung_box_p", u.ljung_box_p},
                                {"t_s", {u.t_s.first, u.t_s.second}},
                                {"correlates_with", u.correlates_with}});
  }
  // -infinity (no candidate passed the held-out test on that replicate) is written as null.
  j["null_bootstrap"] = {{"threshold", d.null_bootstrap.threshold},
                         {"replicate_scores", d.null_bootstrap.replicate_scores}};
  j["thermal_null_bootstrap"] = {{"threshold", d.thermal_null_bootstrap.threshold},
                                 {"replicate_scores", d.thermal_null_bootstrap.replicate_scores},
                                 {"data_score", d.thermal_null_bootstrap.data_score}};
  j["score_block_s"] = {{"min", d.score_block_s.first}, {"max", d.score_block_s.second}};
  if (poly != nullptr && poly->bias_left) {
    const BiasLeft& l = *poly->bias_left;
    const double ratio = l.RmsOverNoise();
    j["left"] = {{"bias_rms_dph", l.rms_dph},
                 {"noise_dph", l.noise_dph},
                 {"rms_over_noise", std::isfinite(ratio) ? nlohmann::json(ratio) : nlohmann::json(nullptr)},
                 {"at_noise", LeftAtNoise(l)},
                 {"largest_correlation", {{"with", l.covariate}, {"r", l.r}}},
                 {"null_correlation", l.null_r}};
  }
  j["notes"] = d.notes;
  return j;
}

}  // namespace

nlohmann::json DiagnosisJson(const Diagnosis& d) { return Json(d, &d, nullptr); }

nlohmann::json DiagnosisJson(const DiagnosisWithoutNetwork& d) { return Json(d, nullptr, &d); }

}  // namespace rlg::diagnosis
