#include "diagnosis/report.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <iterator>
#include <limits>
#include <utility>

#include "diagnosis/catalog/effect_search.h"

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
          {"parameters", c.parameters}, {"kind", KindName(c.kind)}};
}

}  // namespace

std::vector<sim::RangeViolation> OutsidePlausibleRange(const Candidate& c) {
  const EffectSearch* effect = FindSearch(c.cause);
  return effect ? effect->OutsidePlausibleRange(c.parameters) : std::vector<sim::RangeViolation>{};
}

std::string StandInText(const Candidate& c) {
  const auto outside = OutsidePlausibleRange(c);
  if (outside.empty()) return "";
  std::vector<std::string> what;
  for (const auto& v : outside) {
    what.push_back(fmt::format("{} = {:.4g} {} (plausible {:.3g} to {:.3g}: {})", v.parameter->name, v.value,
                               v.parameter->unit, v.parameter->lo, v.parameter->hi, v.parameter->source));
  }
  return fmt::format("{} was fitted at an implausible size, {}: the data do not bound it there, or the catalog's cause "
                     "stands in for something it does not hold",
                     c.cause, fmt::join(what, ", "));
}

double BiasLeft::RmsOverNoise() const {
  if (noise_dph > 0.0) return rms_dph / noise_dph;
  return rms_dph > 0.0 ? std::numeric_limits<double>::infinity() : 0.0;
}

bool LeftAtNoise(const BiasLeft& l) { return !(l.RmsOverNoise() > kAllClearRmsOverNoise); }

std::string LeftText(const BiasLeft& l, const std::string& score_block) {
  const double ratio = l.RmsOverNoise();
  return fmt::format("the held-out residual is {:.3g} °/h RMS on {} means, {} the white noise of such a mean ({:.2g} °/h)",
                     l.rms_dph, score_block, std::isfinite(ratio) ? fmt::format("{:.1f}x", ratio) : std::string("beyond"),
                     l.noise_dph);
}

double HeadlineRmsRatio(const Diagnosis& d) {
  if (d.steps.empty()) return 1.0;
  const Candidate& first = d.steps.front().accepted;
  if (d.has_bias && d.extended.bias_rms_dph > 0.0 && first.kind == CandidateKind::kBias) {
    return d.baseline.bias_rms_dph / d.extended.bias_rms_dph;
  }
  return first.heldout_rms_ratio;
}

double CompensatedStabilityRatio(const Diagnosis& d) {
  double stability = 1.0;
  for (const auto& s : d.steps) stability *= s.compensated_stability_ratio;
  return stability;
}

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

nlohmann::json DiagnosisJson(const Diagnosis& d) {
  nlohmann::json j;
  const bool none = d.steps.empty();
  j["cause"] = none ? "none" : d.steps.front().accepted.cause;
  j["target"] = none ? "" : d.steps.front().accepted.target;
  j["parameters"] = none ? nlohmann::json::object() : nlohmann::json(d.steps.front().accepted.parameters);
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
      a["ties"].push_back({{"cause", t.cause}, {"target", t.target}, {"score_difference", t.score_difference},
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
  j["calibrated"] = d.calibrated;
  j["calibration"] = CalibrationJson(d.calibration);
  j["identifiability"] = diagnosis::IdentifiabilityNotes(d.identifiability);
  j["identifiability_directions"] = IdentifiabilityJson(d.identifiability);
  j["detected_steps"] = nlohmann::json::array();
  for (const auto& st : d.detected_steps) {
    j["detected_steps"].push_back({{"run", st.run}, {"t_s", st.t_s}, {"size_dph", st.size}, {"statistic", st.statistic},
                                   {"threshold", st.threshold}});
  }
  nlohmann::json corr = nlohmann::json::object();
  for (size_t a = 0; a < d.knob_names.size(); ++a)
    for (size_t b = 0; b < d.knob_names.size(); ++b)
      corr[d.knob_names[a]][d.knob_names[b]] = d.knob_correlations(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
  j["parameter_correlations"] = corr;
  j["ljung_box_p"] = d.ljung_box_p;
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
  if (d.bias_left) {
    const BiasLeft& l = *d.bias_left;
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

std::string CalibrationLine(const CalibrationSummary& c, size_t n) {
  std::vector<const KnobCalibration*> by_shift;
  for (const auto& k : c.knobs) by_shift.push_back(&k);
  std::stable_sort(by_shift.begin(), by_shift.end(), [](const KnobCalibration* a, const KnobCalibration* b) {
    return std::abs(a->shift_sigma) > std::abs(b->shift_sigma);
  });
  std::vector<std::string> largest;
  for (size_t i = 0; i < std::min(n, by_shift.size()); ++i) {
    const KnobCalibration& k = *by_shift[i];
    largest.push_back(fmt::format("{} {:.4g} (nominal {:.4g}, {:+.1f} sd)", k.name, k.calibrated, k.nominal, k.shift_sigma));
  }
  const auto conflicts = c.PriorConflicts();
  return fmt::format("calibration: largest shifts from nominal (prior sd {:.3g} in log units): {}; prior conflicts "
                     "(beyond {:g} sd): {}; jointly, sum of squared shifts {:.1f} over {} knobs (p = {:.2g}){}{}",
                     c.prior_sd, fmt::join(largest, ", "), kPriorConflictSigma,
                     conflicts.empty() ? std::string("none") : fmt::format("{}", fmt::join(conflicts, ", ")),
                     c.JointShiftChi2(), c.knobs.size(), c.JointShiftP(),
                     c.JointConflict() ? ": the knobs together are in conflict with the nominal's stated uncertainty; "
                                         "the nominal is off by more than it says, or the network lacks structure"
                                       : "",
                     c.start_capacity_scale == 1.0
                         ? std::string()
                         : fmt::format("; fitted from every heat capacity x {:.3g} (the fit from the nominal ended in a "
                                       "prior conflict and fitted the data worse)",
                                       c.start_capacity_scale));
}

std::string ScoreBlockText(const Diagnosis& d) {
  // Three digits, compared as printed: 1000 samples of 0.1 s are not 100.0 s to the last bit.
  const std::string lo = fmt::format("{:.3g}", d.score_block_s.first), hi = fmt::format("{:.3g}", d.score_block_s.second);
  return lo == hi ? lo + " s" : lo + "-" + hi + " s";
}

std::vector<std::string> StrongCorrelations(const Diagnosis& d, double min_abs, size_t n) {
  std::vector<std::pair<double, std::string>> pairs;
  for (size_t a = 0; a < d.knob_names.size(); ++a) {
    for (size_t b = a + 1; b < d.knob_names.size(); ++b) {
      const double r = d.knob_correlations(static_cast<Eigen::Index>(a), static_cast<Eigen::Index>(b));
      if (std::abs(r) >= min_abs) pairs.emplace_back(-std::abs(r), fmt::format("{} ~ {} {:+.2f}", d.knob_names[a], d.knob_names[b], r));
    }
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<std::string> out;
  for (size_t i = 0; i < std::min(n, pairs.size()); ++i) out.push_back(pairs[i].second);
  return out;
}

std::string BaselineName(const Diagnosis& d) {
  return d.polynomial_order > 0 ? fmt::format("the best polynomial in {} (order {})", d.polynomial_channel, d.polynomial_order)
                                : std::string("the calibrated nominal model");
}

namespace {

/// " T1 0.0123 °C T2 0.0456 °C, bias 0.0789 °/h" (no comma before the bias without temperatures).
std::string MetricsText(const Metrics& m, bool bias) {
  std::string text;
  for (const auto& [ch, v] : m.temperature_rms_C) text += fmt::format(" {} {:.4f} °C", ch, v);
  if (bias) text += fmt::format("{} bias {:.4f} °/h", m.temperature_rms_C.empty() ? "" : ",", m.bias_rms_dph);
  return text;
}

}  // namespace

std::string DiagnosisText(const Diagnosis& d, const DiagnosisTextOptions& options) {
  std::string text;
  auto out = std::back_inserter(text);
  if (d.polynomial_order > 0) {
    fmt::format_to(out, "Diagnosis of {} without a thermal network (bias against measured temperatures)\n",
                   options.data_name);
    fmt::format_to(out, "Baseline ({}), held-out RMS on {} means:", BaselineName(d), ScoreBlockText(d));
  } else {
    fmt::format_to(out, "Diagnosis of {} against {} ({} data)\n", options.data_name, options.gyro_name,
                   d.has_bias ? "bias and temperature" : "thermal-only");
    fmt::format_to(out, "Baseline (calibrated nominal), held-out RMS on {} means:", ScoreBlockText(d));
  }
  fmt::format_to(out, "{}\n", MetricsText(d.baseline, d.has_bias));
  for (const auto& [ch, p] : d.ljung_box_p) fmt::format_to(out, "  Ljung-Box p ({} residuals, 10 lags): {:.3g}\n", ch, p);
  if (!d.calibration.knobs.empty()) fmt::format_to(out, "  {}\n", CalibrationLine(d.calibration));
  for (const auto& note : diagnosis::IdentifiabilityNotes(d.identifiability))
    fmt::format_to(out, "  identifiability: {}\n", note);
  for (const auto& pair : StrongCorrelations(d, options.min_correlation, options.max_correlations))
    fmt::format_to(out, "  posterior correlation: {}\n", pair);
  for (const auto& note : d.notes) fmt::format_to(out, "  {}\n", note);
  fmt::format_to(out, "\nCandidates of the first search (best first):\n");
  for (size_t i = 0; i < std::min(options.max_candidates, d.first_candidates.size()); ++i) {
    const auto& c = d.first_candidates[i];
    fmt::format_to(out, "  {:<24} {:<18} score {:>10.1f}  held-out RMS ratio {:.3f}\n", c.cause, c.target, c.score,
                   c.heldout_rms_ratio);
  }
  if (d.steps.empty())
    fmt::format_to(out, "\ncause: none (no candidate is significant){}\n",
                   d.unexplained.empty() ? "" : "; the model still misses the data: see 'unexplained' below");
  for (size_t i = 0; i < d.steps.size(); ++i) {
    const auto& s = d.steps[i];
    fmt::format_to(out, "\nstep {}: {} on {}", i + 1, s.accepted.cause, s.accepted.target);
    for (const auto& [k, v] : s.accepted.parameters) fmt::format_to(out, ", {} = {:.5g}", k, v);
    fmt::format_to(out, "\n  score {:.1f} (needed {:.1f}), held-out RMS ratio {:.3f}", s.accepted.score, s.threshold,
                   s.accepted.heldout_rms_ratio);
    if (s.accepted.kind == CandidateKind::kBias)
      fmt::format_to(out, ", compensated {} stability ratio {:.3f}", ScoreBlockText(d), s.compensated_stability_ratio);
    fmt::format_to(out, "\n  held-out RMS before -> after:");
    for (const auto& [ch, v] : s.before.temperature_rms_C)
      fmt::format_to(out, " {} {:.4f} -> {:.4f} °C", ch, v, s.after.temperature_rms_C.at(ch));
    if (d.has_bias)
      fmt::format_to(out, "{} bias {:.4f} -> {:.4f} °/h", s.before.temperature_rms_C.empty() ? "" : ",",
                     s.before.bias_rms_dph, s.after.bias_rms_dph);
    fmt::format_to(out, "\n");
    if (!s.knob_shifts.empty()) {
      std::vector<std::string> moved;
      for (const auto& k : s.knob_shifts)
        moved.push_back(fmt::format("{} {:+.1f} -> {:+.1f} sd", k.name, k.before_sigma, k.after_sigma));
      fmt::format_to(out, "  knobs (shift from nominal in prior sds, before -> after this step): {}\n", fmt::join(moved, ", "));
    }
    for (const auto& n : s.notes) fmt::format_to(out, "  note: {}\n", n);
    if (const std::string stand_in = StandInText(s.accepted); !stand_in.empty()) fmt::format_to(out, "  stand-in: {}\n", stand_in);
  }
  if (!d.unexplained.empty()) {
    fmt::format_to(out, "{}", d.polynomial_order > 0
                                  ? "\nunexplained (well above the noise, not white and moving with the temperature more "
                                    "than noise does after the last step; no candidate took it up):\n"
                                  : "\nunexplained (well above the noise and not white after the last step; no catalog cause "
                                    "took it up):\n");
    for (const auto& u : d.unexplained) fmt::format_to(out, "  {}\n", diagnosis::UnexplainedText(u));
  }
  if (d.bias_left) fmt::format_to(out, "\nleft: {}\n", LeftText(*d.bias_left, ScoreBlockText(d)));
  fmt::format_to(out, "\nverdict: {}\n", DiagnosisVerdict(d));
  return text;
}

namespace {

/// The verdict without a thermal network: what the best polynomial misses with its held-out
/// gain, or `unexplained` with where and with what, or `none`.
std::string PolynomialVerdict(const Diagnosis& d) {
  std::vector<std::string> where;
  for (const auto& u : d.unexplained) {
    std::vector<std::pair<std::string, double>> by_size(u.correlates_with.begin(), u.correlates_with.end());
    std::stable_sort(by_size.begin(), by_size.end(),
                     [](const auto& a, const auto& b) { return std::abs(a.second) > std::abs(b.second); });
    std::vector<std::string> moves;
    for (const auto& [name, r] : by_size) moves.push_back(fmt::format("{} (r = {:+.2f})", name, r));
    where.push_back(fmt::format("over t = {:.0f}-{:.0f} s of {} moves with {} (its RMS {:.1f}x the noise of its {} "
                                "means, {:.2g} °/h)",
                                u.t_s.first, u.t_s.second, u.run, fmt::join(moves, ", "), u.rms_over_noise,
                                ScoreBlockText(d), u.noise));
  }
  // What stays when no unit passes the unexplained test: at the noise, an all-clear; above it,
  // how large it is and that noise as slow as its own could move with the temperature as much,
  // so that nothing here names it: no all-clear over a residual many times the noise.
  std::string left_over;
  if (where.empty() && d.bias_left && !LeftAtNoise(*d.bias_left)) {
    const BiasLeft& l = *d.bias_left;
    left_over = fmt::format(
        "{}, and nothing names it: its largest correlation, with {}, is r = {:+.2f}, no more than slow noise reaches "
        "({:.2f} on {} replicates of AR noise fitted to the residuals of every candidate at once, into which a misfit no "
        "candidate takes up enters too); a missing term and slow noise are not told apart here",
        LeftText(l, ScoreBlockText(d)), l.covariate.empty() ? std::string("the temperature") : l.covariate, l.r, l.null_r,
        l.replicates);
  }
  if (d.steps.empty()) {
    const std::string best =
        d.first_candidates.empty()
            ? std::string()
            : fmt::format(" (the best, {} on {}, scores {:.1f} of the {:.1f} needed, held-out RMS ratio {:.2f})",
                          d.first_candidates.front().cause, d.first_candidates.front().target,
                          d.first_candidates.front().score, d.null_bootstrap.threshold,
                          d.first_candidates.front().heldout_rms_ratio);
    if (where.empty() && !left_over.empty())
      return fmt::format("unexplained: no candidate is significant against {}{}; {}", BaselineName(d), best, left_over);
    if (where.empty() && d.bias_left)
      return fmt::format("none: no candidate is significant against {}{}, and its residual is at the noise ({})",
                         BaselineName(d), best, LeftText(*d.bias_left, ScoreBlockText(d)));
    if (where.empty())  // a record without its size (none made by DiagnoseWithoutNetwork)
      return fmt::format("none: no candidate is significant against {}{}, and its residual moves with the temperature "
                         "no more than noise as slow as its own does",
                         BaselineName(d), best);
    return fmt::format("unexplained: no candidate is significant against {}{}, but its residual {}", BaselineName(d), best,
                       fmt::join(where, "; "));
  }
  std::vector<std::string> named;
  for (const auto& s : d.steps) {
    std::vector<std::string> params;
    for (const auto& [k, v] : s.accepted.parameters) params.push_back(fmt::format("{} = {:.4g}", k, v));
    named.push_back(fmt::format("{} on {} ({}; score {:.1f} of the {:.1f} needed, held-out RMS ratio {:.2f})",
                                s.accepted.cause, s.accepted.target, fmt::join(params, ", "), s.accepted.score,
                                s.threshold, s.accepted.heldout_rms_ratio));
  }
  std::string rest;
  if (!where.empty())
    rest = fmt::format("unexplained: the residual {}", fmt::join(where, "; "));
  else if (!left_over.empty())
    rest = "unexplained: " + left_over;
  else
    rest = d.bias_left ? fmt::format("what is left is at the noise ({})", LeftText(*d.bias_left, ScoreBlockText(d)))
                       : std::string("nothing that moves with the temperature is left unexplained");
  return fmt::format("{} misses {}; {}", BaselineName(d), fmt::join(named, ", then "), rest);
}

}  // namespace

std::string DiagnosisVerdict(const Diagnosis& d) {
  if (d.polynomial_order > 0) return PolynomialVerdict(d);
  const std::string misses = "the model still misses the data where no catalog effect explains it (see unexplained)";
  if (d.steps.empty()) {
    return d.unexplained.empty() ? "no effect added: the calibrated nominal model leaves nothing well above the noise unexplained"
                                 : "no catalog effect is significant; " + misses;
  }
  std::vector<std::string> named;
  for (const auto& s : d.steps) {
    named.push_back(fmt::format("{} on {}{}", s.accepted.cause, s.accepted.target,
                                StandInText(s.accepted).empty() ? "" : " (a stand-in, outside its plausible range)"));
  }
  return fmt::format("{} added ({}); {}", d.steps.size() == 1 ? "one effect" : fmt::format("{} effects", d.steps.size()),
                     fmt::join(named, ", then "),
                     d.unexplained.empty() ? "nothing well above the noise is left unexplained" : misses);
}

std::vector<double> RatePerMinute(const std::vector<double>& t, const std::vector<double>& T) {
  std::vector<double> r(T.size(), std::numeric_limits<double>::quiet_NaN());
  if (T.size() < 2) return r;
  for (size_t i = 0; i < T.size(); ++i) {
    const size_t a = i == 0 ? 0 : i - 1, b = std::min(i + 1, T.size() - 1);
    r[i] = 60.0 * (T[b] - T[a]) / (t[b] - t[a]);
  }
  return r;
}

std::vector<double> GroupMeans(const std::vector<double>& v, size_t g) {
  std::vector<double> out;
  for (size_t i = 0; i + g <= v.size(); i += g) {
    double sum = 0.0;
    for (size_t k = i; k < i + g; ++k) sum += v[k];
    out.push_back(sum / static_cast<double>(g));
  }
  return out;
}

std::string BiasTemperatureChannel(const sim::GyroConfig& gyro) {
  for (const auto& s : gyro.sensors)
    if (s.node == gyro.bias.node) return s.channel;
  return gyro.sensors.front().channel;
}

namespace {

/// The report's channels: those of the first run's residuals, in name order.
std::vector<std::string> ReportChannels(const Diagnosis& d) {
  std::vector<std::string> channels;
  if (!d.residuals.empty())
    for (const auto& [ch, v] : d.residuals.front().measured) channels.push_back(ch);
  return channels;
}

/// Some run has the baseline's residuals of channel `ch` (every channel of a diagnosis against a
/// gyro; only the bias without a thermal network).
bool Modelled(const Diagnosis& d, const std::string& ch) {
  return std::any_of(d.residuals.begin(), d.residuals.end(), [&ch](const ResidualTrace& tr) { return tr.baseline.count(ch) > 0; });
}

std::vector<double> Head(const std::vector<double>& v, size_t n) {
  return {v.begin(), v.begin() + static_cast<std::ptrdiff_t>(n)};
}

}  // namespace

ResidualTable MakeResidualTable(const Diagnosis& d) {
  using Kind = ResidualColumn::Kind;
  ResidualTable table;
  const std::vector<std::string> channels = ReportChannels(d);
  for (const auto& ch : channels) {
    table.columns.push_back({"measured_" + ch, ch, Kind::kMeasured});
    if (ch != "bias_dph") table.columns.push_back({"dTdt_" + ch + "_C_per_min", ch, Kind::kRate});
    if (!Modelled(d, ch)) continue;  // measured only (a temperature without a thermal network)
    table.columns.push_back({"baseline_" + ch, ch, Kind::kBaseline});
    table.columns.push_back({"extended_" + ch, ch, Kind::kExtended});
  }
  for (const auto& tr : d.residuals) {
    ResidualTableRun run;
    run.run = tr.run;
    run.t_s = tr.t_s;
    for (const auto& column : table.columns) {
      const std::string& ch = column.channel;
      const auto m = tr.measured.find(ch), b = tr.baseline.find(ch), e = tr.extended.find(ch);
      const bool modelled = b != tr.baseline.end() && e != tr.extended.end();
      std::vector<double> values;
      if (m != tr.measured.end() && !modelled) {  // data only: a channel no model predicts, or unscored stretches
        const size_t n = std::min(tr.t_s.size(), m->second.size());
        if (column.kind == Kind::kMeasured) values = Head(m->second, n);
        if (column.kind == Kind::kRate) values = Head(RatePerMinute(tr.t_s, m->second), n);
      } else if (m != tr.measured.end()) {
        const size_t n = std::min({tr.t_s.size(), m->second.size(), b->second.size(), e->second.size()});
        switch (column.kind) {
          case Kind::kMeasured: values = Head(m->second, n); break;
          case Kind::kRate: values = Head(RatePerMinute(tr.t_s, m->second), n); break;
          case Kind::kBaseline: values = Head(b->second, n); break;
          case Kind::kExtended: values = Head(e->second, n); break;
        }
      }
      run.values.push_back(std::move(values));
    }
    table.runs.push_back(std::move(run));
  }
  return table;
}

DiagnosisFigures MakeDiagnosisFigures(const Diagnosis& d, const std::string& bias_temperature) {
  DiagnosisFigures figures;
  figures.score_block_s = d.score_block_s.second;
  figures.extended = !d.steps.empty();
  for (const auto& ch : ReportChannels(d)) {
    if (!Modelled(d, ch)) continue;  // no model of it to show (a temperature without a thermal network)
    ChannelFigure figure;
    figure.channel = ch;
    figure.temperature = ch == "bias_dph" ? bias_temperature : ch;
    for (const auto& tr : d.residuals) {
      const auto m = tr.measured.find(ch), b = tr.baseline.find(ch), e = tr.extended.find(ch);
      const auto T = tr.measured.find(figure.temperature);
      if (m == tr.measured.end() || b == tr.baseline.end() || e == tr.extended.end() || T == tr.measured.end()) continue;
      const size_t n = std::min({m->second.size(), b->second.size(), e->second.size(), T->second.size(), tr.t_s.size()});
      if (n == 0) continue;
      ChannelFigureRun run;
      run.run = tr.run;
      run.t_s = Head(tr.t_s, n);
      run.measured = Head(m->second, n);
      run.simulated_baseline.resize(n);
      run.simulated_extended.resize(n);
      for (size_t i = 0; i < n; ++i) {
        run.simulated_baseline[i] = m->second[i] - b->second[i];
        run.simulated_extended[i] = m->second[i] - e->second[i];
      }
      const double spacing = n > 1 ? (tr.t_s[n - 1] - tr.t_s[0]) / static_cast<double>(n - 1) : figures.score_block_s;
      const size_t g = static_cast<size_t>(std::max(1.0, std::round(figures.score_block_s / spacing)));
      run.blocks_per_score_block = g;
      const std::vector<double> temperature = Head(T->second, n);
      run.residual_baseline = GroupMeans(Head(b->second, n), g);
      run.residual_extended = GroupMeans(Head(e->second, n), g);
      run.temperature_C = GroupMeans(temperature, g);
      run.rate_C_per_min = GroupMeans(RatePerMinute(run.t_s, temperature), g);
      figure.runs.push_back(std::move(run));
    }
    figures.channels.push_back(std::move(figure));
  }
  return figures;
}

}  // namespace rlg::diagnosis
