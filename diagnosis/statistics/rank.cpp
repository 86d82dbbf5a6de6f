#include "diagnosis/statistics/rank.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <numeric>
#include <set>

#include "diagnosis/catalog/effect_search.h"

namespace rlg::diagnosis {

bool PlausibleFit(const Candidate& c) {
  const EffectSearch* e = FindSearch(c.cause);
  return e == nullptr || e->OutsidePlausibleRange(c.parameters).empty();
}

namespace {

/// Effect::Implausibility; 1 for a cause outside the catalog.
double ImplausibilityOf(const Candidate& c) {
  const EffectSearch* e = FindSearch(c.cause);
  return e == nullptr ? 1.0 : e->Implausibility(c.parameters);
}

}  // namespace

RankingRule RankingRule::WithNetwork(const DiagnoseOptions& o, double thermal_threshold, double bias_threshold) {
  RankingRule rule;
  rule.thermal_threshold = thermal_threshold;
  rule.bias_threshold = bias_threshold;
  rule.min_heldout_gain = o.min_heldout_gain;
  rule.tie_score = o.tie_score;
  return rule;
}

RankingRule RankingRule::WithoutNetwork(const DiagnoseOptions& o, double bias_threshold) {
  RankingRule rule = WithNetwork(o, o.min_score, bias_threshold);
  rule.min_heldout_ratio = o.min_heldout_ratio;
  rule.plausible_first = false;
  return rule;
}

bool Significant(const Candidate& c, const RankingRule& rule) {
  if (c.kind != CandidateKind::kThermal && c.kind != CandidateKind::kBias) return false;
  const bool thermal = c.kind == CandidateKind::kThermal;
  return c.score >= (thermal ? rule.thermal_threshold : rule.bias_threshold) && c.heldout_gain > rule.min_heldout_gain &&
         c.heldout_rms_ratio >= rule.min_heldout_ratio;
}

size_t CountSignificant(const std::vector<Candidate>& candidates, const RankingRule& rule) {
  return static_cast<size_t>(
      std::count_if(candidates.begin(), candidates.end(), [&](const Candidate& c) { return Significant(c, rule); }));
}

std::vector<size_t> Rank(const std::vector<Candidate>& cands, const RankingRule& rule) {
  std::vector<size_t> order(cands.size());
  std::iota(order.begin(), order.end(), 0);
  // Significant thermal candidates first, then significant bias candidates, each by score; the
  // rest after them. (A thermal candidate whose score beats a significant bias candidate's but
  // which fails the held-out test must not come first and end the search with "none": the
  // worked example's hidden rate, held-out ratio 3.1, would go unnamed.)
  auto thermal = [&](size_t i) { return IsThermal(cands[i].kind); };
  // Within a kind, a significant candidate fitted inside its catalog range (a cause) comes before
  // one fitted outside it (a stand-in for something the catalog does not hold): on TCLab a heater
  // power falling 2.6 %/°C out-scores the link between the heaters by 12 points; taken first,
  // it would leave the link, physically there, never accepted.
  std::vector<char> plausible(cands.size());
  for (size_t i = 0; i < cands.size(); ++i)
    plausible[i] = Significant(cands[i], rule) && (!rule.plausible_first || PlausibleFit(cands[i]));
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    const bool sa = Significant(cands[a], rule), sb = Significant(cands[b], rule);
    if (sa != sb) return sa;
    if (sa && thermal(a) != thermal(b)) return thermal(a);
    if (sa && plausible[a] != plausible[b]) return plausible[a] != 0;
    return cands[a].score > cands[b].score;
  });
  // Candidates whose scores agree to tie_score are exact twins, one prediction under two
  // names: the rate of a node with a single link is that link's gradient, and a gradient is
  // known only up to the gradients already in the model. Among them the one that predicts the
  // held-out runs best is taken; as twins tie there too, in practice the most plausible
  // (smallest parameter on the catalog's scale). Near ties stay ranked by score: ranking
  // candidates within 2 points (Burnham & Anderson's band) by held-out RMS instead named 191
  // of 200 blind cases right, by score 196 (two seed sets of the confusion-matrix test):
  // leave-one-run-out is the noisier of the two measures.
  if (order.size() > 1 && Significant(cands[order[0]], rule)) {
    const double top = cands[order[0]].score;
    size_t pick = 0;
    for (size_t i = 1; i < order.size(); ++i) {
      const Candidate& c = cands[order[i]];
      if (c.kind != cands[order[0]].kind || std::abs(top - c.score) >= rule.tie_score || !Significant(c, rule)) break;
      const Candidate& p = cands[order[pick]];
      const double dh = c.heldout_gain - p.heldout_gain;
      if (dh > 1e-9 || (dh > -1e-9 && ImplausibilityOf(c) < ImplausibilityOf(p)))
        pick = i;
    }
    std::rotate(order.begin(), order.begin() + static_cast<std::ptrdiff_t>(pick),
                order.begin() + static_cast<std::ptrdiff_t>(pick) + 1);
  }
  return order;
}

std::vector<Tie> Ties(const std::vector<Candidate>& ranked, const RankingRule& rule,
                      const std::vector<double>& score_differences) {
  std::vector<Tie> ties;
  if (ranked.empty() || !Significant(ranked.front(), rule)) return ties;
  const Candidate& lead = ranked.front();
  for (size_t i = 1; i < ranked.size(); ++i) {
    const Candidate& c = ranked[i];
    if (c.kind != lead.kind || !Significant(c, rule)) continue;
    const bool plausible = PlausibleFit(c);
    // Named apart only where both the fit data and the held-out data prefer the leader by the
    // band: refgen's cathode power drift at 1 s trailed a block drift by 21 score points while
    // the held-out data preferred the block by 0.9 (a misfit the in-sample score weighs and the
    // held-out data do not confirm).
    const double paired = i < score_differences.size() ? score_differences[i] : std::nan("");
    const double ds = std::isnan(paired) ? c.score - lead.score : paired, dh = c.heldout_gain - lead.heldout_gain;
    const bool ambiguous = std::abs(ds) < kTieBand || dh > -kTieBand;
    // A stand-in that out-scored the leader by more than the band was ranked after it only for
    // its size (Rank): the report still says the data preferred it (the refgen rate terms of
    // 1.06-1.24 °/h per °C/min, above the catalog's 1, out-scored a gradient by 17 points).
    const bool set_aside = !plausible && ds >= kTieBand;
    if (set_aside || ambiguous) ties.push_back({c.cause, c.target, ds, plausible, dh, ambiguous && !set_aside});
  }
  return ties;
}

std::vector<std::string> TieNotes(const Candidate& leader, const std::vector<Tie>& ties, bool has_logged_ambient,
                                  double tie_score) {
  std::vector<std::string> listed, set_aside, twins;
  std::set<std::string> tied_causes = {leader.cause};  // of the ties that are not exact twins
  for (const Tie& t : ties) {
    const std::string item = fmt::format("{} {} ({:+.1f}, held out {:+.1f}{})", t.cause, t.target, t.score_difference,
                                         t.heldout_difference, t.plausible ? "" : ", stand-in");
    if (!t.ambiguous) {
      set_aside.push_back(item);
      continue;
    }
    listed.push_back(item);
    if (std::abs(t.score_difference) < tie_score) {
      twins.push_back(fmt::format("{} {}", t.cause, t.target));
    } else {
      tied_causes.insert(t.cause);
    }
  }
  std::vector<std::string> notes;
  if (!listed.empty()) {
    // What would separate them. Exact twins, one prediction under several names: no advice
    // (docs/diagnosis.md says which stay twins on any run). For the rest, an effect's own advice
    // where it has one for this tie (gradients among themselves, an offset with the ambient
    // unlogged), else the near-collinear pairs of docs/diagnosis.md for the bias terms and point
    // 4 for the thermal ones.
    std::vector<std::string> what;
    if (!twins.empty()) {
      what.push_back(fmt::format("exact twins of it on these data (one prediction under several names; "
                                 "docs/diagnosis.md says which stay twins on any run): {}",
                                 fmt::join(twins, ", ")));
    }
    if (twins.size() < listed.size()) {
      std::string advice;
      for (const auto& cause : tied_causes) {
        const EffectSearch* effect = FindSearch(cause);
        if (effect != nullptr) advice = effect->SeparationAdvice(tied_causes, has_logged_ambient);
        if (!advice.empty()) break;
      }
      if (advice.empty() && leader.kind == CandidateKind::kBias) {
        advice = "a step or a dwell in ambient, or another ramp rate, separates rate from gradient terms and "
                 "hysteresis from both";
      } else if (advice.empty()) {
        advice = "more temperature span and faster dynamics separate sensor lag from a missing mass and radiation "
                 "from a larger linear coupling";
      }
      what.push_back(advice);
    }
    notes.push_back(fmt::format("ambiguous: within {:g} score points of {} {} on the fit or the held-out data: {}; {}",
                                kTieBand, leader.cause, leader.target, fmt::join(listed, ", "),
                                fmt::join(what, "; ")));
  }
  if (!set_aside.empty())
    notes.push_back(fmt::format("set aside: the data prefer {} to {} {}, but only at a size outside the catalog's "
                                "plausible range (a stand-in for something the catalog does not hold, or the range "
                                "is too narrow for this gyro)",
                                fmt::join(set_aside, ", "), leader.cause, leader.target));
  return notes;
}

}  // namespace rlg::diagnosis
