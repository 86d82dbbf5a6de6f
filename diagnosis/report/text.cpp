// The text of a diagnosis (report.h): the summary, the calibration line, the verdict.

#include "diagnosis/report.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <iterator>
#include <utility>

#include "diagnosis/statistics/rank.h"

namespace rlg::diagnosis {

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

std::string ScoreBlockText(const SearchRecord& d) {
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

std::string BaselineName(const Diagnosis&) { return "the calibrated nominal model"; }

std::string BaselineName(const DiagnosisWithoutNetwork& d) {
  return fmt::format("the best polynomial in {} (order {})", d.polynomial_channel, d.polynomial_order);
}

namespace {

/// " T1 0.0123 °C T2 0.0456 °C, bias 0.0789 °/h" (no comma before the bias without temperatures).
std::string MetricsText(const Metrics& m, bool bias) {
  std::string text;
  for (const auto& [ch, v] : m.temperature_rms_C) text += fmt::format(" {} {:.4f} °C", ch, v);
  if (bias) text += fmt::format("{} bias {:.4f} °/h", m.temperature_rms_C.empty() ? "" : ",", m.bias_rms_dph);
  return text;
}

/// The text of either record: `network` set for a diagnosis against a gyro, `poly` without a
/// network; `verdict` its DiagnosisVerdict.
std::string Text(const SearchRecord& d, const Diagnosis* network, const DiagnosisWithoutNetwork* poly,
                 const std::string& verdict, const DiagnosisTextOptions& options) {
  std::string text;
  auto out = std::back_inserter(text);
  if (poly != nullptr) {
    fmt::format_to(out, "Diagnosis of {} without a thermal network (bias against measured temperatures)\n",
                   options.data_name);
    fmt::format_to(out, "Baseline ({}), held-out RMS on {} means:", BaselineName(*poly), ScoreBlockText(d));
  } else {
    fmt::format_to(out, "Diagnosis of {} against {} ({} data)\n", options.data_name, options.gyro_name,
                   d.has_bias ? "bias and temperature" : "thermal-only");
    fmt::format_to(out, "Baseline (calibrated nominal), held-out RMS on {} means:", ScoreBlockText(d));
  }
  fmt::format_to(out, "{}\n", MetricsText(d.baseline, d.has_bias));
  for (const auto& [ch, p] : d.ljung_box_p) fmt::format_to(out, "  Ljung-Box p ({} residuals, 10 lags): {:.3g}\n", ch, p);
  if (network != nullptr) {
    if (!network->calibration.knobs.empty()) fmt::format_to(out, "  {}\n", CalibrationLine(network->calibration));
    for (const auto& note : diagnosis::IdentifiabilityNotes(network->identifiability))
      fmt::format_to(out, "  identifiability: {}\n", note);
    for (const auto& pair : StrongCorrelations(*network, options.min_correlation, options.max_correlations))
      fmt::format_to(out, "  posterior correlation: {}\n", pair);
  }
  for (const auto& note : d.notes) fmt::format_to(out, "  {}\n", note);
  // The order is Rank's (statistics/rank.h), not the score's: say so, and mark the stand-ins and
  // where the significant candidates end.
  fmt::format_to(out, "\nCandidates of the first search, ranked: the significant first ({}), then the rest by score:\n",
                 network != nullptr ? "thermal before bias, causes before stand-ins, each by score" : "by score");
  for (size_t i = 0; i < std::min(options.max_candidates, d.first_candidates.size()); ++i) {
    const auto& c = d.first_candidates[i];
    if (i == d.first_significant)
      fmt::format_to(out, "  not significant (below the acceptance score, or no held-out gain):\n");
    fmt::format_to(out, "  {:<24} {:<18} score {:>10.1f}  held-out gain {:>8.1f}  RMS ratio {:.3f}{}\n", c.cause, c.target,
                   c.score, c.heldout_gain, c.heldout_rms_ratio,
                   i < d.first_significant && !PlausibleFit(c) ? "  stand-in (outside the catalog's plausible range)" : "");
  }
  if (network != nullptr && !network->power.empty()) {
    fmt::format_to(out,
                   "\nPower of the first search ({:.0f} %: linearised at the calibrated nominal, each signature "
                   "prewhitened as its score is and less what the calibrated knobs (thermal and sensor effects) or "
                   "the baseline bias terms (bias effects) take up; named: ahead of every rival of its kind):\n",
                   100.0 * kPowerLevel);
    for (const auto& e : network->power) {
      fmt::format_to(out, "  {:<24} {:<18} {} ", e.cause, e.target, e.parameter);
      constexpr const char* kBeyond = " (beyond the catalog's plausible range: a stand-in)";
      if (!std::isfinite(e.detected))
        fmt::format_to(out, "never detected (the calibration takes it up)");
      else if (!std::isfinite(e.named))
        fmt::format_to(out, "detected above {:.3g}{}, never named apart", e.detected, e.detected_plausible ? "" : kBeyond);
      else
        fmt::format_to(out, "detected above {:.3g}{}, named above {:.3g}{}", e.detected, e.detected_plausible ? "" : kBeyond,
                       e.named, e.named_plausible ? "" : kBeyond);
      if (!e.rival_cause.empty())
        fmt::format_to(out, " (nearest: {} {}, cosine {:+.3f})", e.rival_cause, e.rival_target, e.rival_cosine);
      fmt::format_to(out, "\n");
    }
  }
  if (d.steps.empty())
    fmt::format_to(out, "\ncause: none (no candidate is significant){}\n",
                   d.unexplained.empty() ? "" : "; the model still misses the data: see 'unexplained' below");
  for (size_t i = 0; i < d.steps.size(); ++i) {
    const auto& s = d.steps[i];
    fmt::format_to(out, "\nstep {}: {} on {}", i + 1, s.accepted.cause, s.accepted.target);
    for (const auto& [k, v] : s.accepted.parameters) fmt::format_to(out, ", {} = {:.5g}", k, v);
    fmt::format_to(out, "\n  score {:.1f} (needed {:.1f}), held-out gain {:.1f}, held-out RMS ratio {:.3f}", s.accepted.score,
                   s.threshold, s.accepted.heldout_gain, s.accepted.heldout_rms_ratio);
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
    fmt::format_to(out, "{}", poly != nullptr
                                  ? "\nunexplained (well above the noise, not white and moving with the temperature more "
                                    "than noise does after the last step; no candidate took it up):\n"
                                  : "\nunexplained (well above the noise and not white after the last step; no catalog cause "
                                    "took it up):\n");
    for (const auto& u : d.unexplained) fmt::format_to(out, "  {}\n", diagnosis::UnexplainedText(u));
  }
  if (poly != nullptr && poly->bias_left)
    fmt::format_to(out, "\nleft: {}\n", LeftText(*poly->bias_left, ScoreBlockText(d)));
  fmt::format_to(out, "\nverdict: {}\n", verdict);
  return text;
}

}  // namespace

std::string DiagnosisText(const Diagnosis& d, const DiagnosisTextOptions& options) {
  return Text(d, &d, nullptr, DiagnosisVerdict(d), options);
}

std::string DiagnosisText(const DiagnosisWithoutNetwork& d, const DiagnosisTextOptions& options) {
  return Text(d, nullptr, &d, DiagnosisVerdict(d), options);
}

namespace {

/// The verdict without a thermal network: what the best polynomial misses with its held-out
/// gain, or `unexplained` with where and with what, or `none`.
std::string PolynomialVerdict(const DiagnosisWithoutNetwork& d) {
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

std::string DiagnosisVerdict(const DiagnosisWithoutNetwork& d) { return PolynomialVerdict(d); }

namespace {

/// " or, not told apart by these data, Y on B or Z on C": the step's ambiguous ties.
std::string AmbiguousText(const DiagnosisStep& s) {
  std::vector<std::string> with;
  for (const Tie& t : s.ties)
    if (t.ambiguous) with.push_back(fmt::format("{} on {}", t.cause, t.target));
  return with.empty() ? "" : fmt::format(" or, not told apart by these data, {}", fmt::join(with, " or "));
}

}  // namespace

std::string DiagnosisVerdict(const Diagnosis& d) {
  const std::string misses = "the model still misses the data where no catalog effect explains it (see unexplained)";
  if (d.steps.empty()) {
    return d.unexplained.empty() ? "no effect added: the calibrated nominal model leaves nothing well above the noise unexplained"
                                 : "no catalog effect is significant; " + misses;
  }
  std::vector<std::string> named;
  for (const auto& s : d.steps) {
    named.push_back(fmt::format("{} on {}{}{}", s.accepted.cause, s.accepted.target,
                                StandInText(s.accepted).empty() ? "" : " (a stand-in, outside its plausible range)",
                                AmbiguousText(s)));
  }
  return fmt::format("{} added ({}); {}", d.steps.size() == 1 ? "one effect" : fmt::format("{} effects", d.steps.size()),
                     fmt::join(named, ", then "),
                     d.unexplained.empty() ? "nothing well above the noise is left unexplained" : misses);
}

}  // namespace rlg::diagnosis
