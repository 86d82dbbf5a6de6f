#pragma once
/// Stage 6 of the diagnosis: ranking the candidates of one search and naming the ties
/// (docs/diagnosis.md: what the data cannot tell apart). Pure functions of the scored candidates.
///
/// A candidate is significant when its information-criterion score reaches the acceptance
/// score of its kind (the thermal or the bias null bootstrap's threshold), its held-out gain
/// (Candidate::heldout_gain) exceeds min_heldout_gain and, without a thermal network, its held-out
/// RMS ratio reaches min_heldout_ratio. Order:
///  1. significant thermal candidates (thermal causes are upstream of the bias): those fitted
///     inside the catalog's plausible range (Effect::OutsidePlausibleRange empty) by score, then
///     the stand-ins fitted outside it, by score;
///  2. significant bias candidates, the same way;
///  3. the rest, by score.
/// Among the leading candidates whose scores agree with the first to `tie_score` (exact twins,
/// one prediction under two names: the rate of a node with a single link is that link's
/// gradient), the one with the best held-out gain leads, then the most plausible (smallest
/// Effect::Implausibility). A tie (Tie) is a significant candidate of the leader's kind that the
/// data do not tell from it (Tie::ambiguous): within kTieBand score points of it (two bias
/// candidates' points under one noise model: network/bias_search.h PairedScores), or whose
/// held-out gain trails the leader's by less than kTieBand (named apart only where the fit data
/// and the held-out data both prefer the leader by the band); or a stand-in of its kind that
/// scored above it by more than the band and was set aside for it (so the report says what the
/// data preferred).

#include <string>
#include <vector>

#include "diagnosis/diagnose.h"

namespace rlg::diagnosis {

/// What makes a candidate significant, and what makes two candidates twins.
struct RankingRule {
  double thermal_threshold = 10.0;         ///< thermal candidates (information units): NullBootstrap::threshold
  double bias_threshold = 10.0;            ///< bias candidates: NullBootstrap::threshold
  double min_heldout_gain = 0.0;           ///< Candidate::heldout_gain must exceed it
  double min_heldout_ratio = 0.0;          ///< Candidate::heldout_rms_ratio must reach it (0: not asked)
  double tie_score = 1e-6;                 ///< exact twins
  /// Significant candidates fitted inside the catalog's plausible range come before stand-ins
  /// (order above); false: by score alone, as without a gyro file, whose kind of gyro the
  /// catalog's ranges (a ring laser gyro's) may not fit (diagnosis/without_network/diagnose.cpp).
  bool plausible_first = true;
  /// The rule of a diagnosis with a thermal network: `options`' held-out gain, the thresholds of
  /// the thermal and the bias null bootstraps.
  static RankingRule WithNetwork(const DiagnoseOptions& options, double thermal_threshold, double bias_threshold);
  /// The rule without one: the bias bootstrap's threshold for every term, `options`'
  /// min_heldout_ratio as well as its gain, and no plausible-first order.
  static RankingRule WithoutNetwork(const DiagnoseOptions& options, double bias_threshold);
};

/// Score (and held-out gain) points within which a significant candidate of the leader's kind is
/// a tie: the data prefer the leader by less than a likelihood ratio of e^5 (information units
/// are 2 ln L).
inline constexpr double kTieBand = 10.0;

/// A candidate whose cause is not an effect of the catalog (a term of the model family tried
/// without a thermal network: poly.lag, poly.hysteresis) has no plausible range: it counts as
/// plausible, of implausibility 1, and has no separation advice of its own.

/// Fitted inside its effect's plausible range (Effect::OutsidePlausibleRange empty); true for a
/// cause outside the catalog.
bool PlausibleFit(const Candidate& c);

/// Kind kThermal or kBias (not kThermalScreened nor kThermalNoEffect), score and
/// held-out ratio at or above the rule's.
bool Significant(const Candidate& c, const RankingRule& rule);
/// How many of `candidates` are Significant (after Rank, the leading ones).
size_t CountSignificant(const std::vector<Candidate>& candidates, const RankingRule& rule);

/// Indices into `candidates`, best first (the order above).
std::vector<size_t> Rank(const std::vector<Candidate>& candidates, const RankingRule& rule);

/// The ties of ranked.front() among `ranked` (best first), in their order; empty when the
/// leader is not significant. `score_differences`, when given, holds per ranked candidate its
/// score less the leader's as the tie rule is to compare them (NaN: the difference of their
/// scores): a bias search's under one noise model (network/bias_search.h PairedScores).
std::vector<Tie> Ties(const std::vector<Candidate>& ranked, const RankingRule& rule,
                      const std::vector<double>& score_differences = {});

/// The step's notes on `ties` of `leader`: an "ambiguous:" note listing the ambiguous ones,
/// then the exact twins among them (score within `tie_score` of the leader's: one prediction,
/// which no advice separates), and for the others what would separate them (an effect's own
/// SeparationAdvice where one of their causes has one, else docs/diagnosis.md's near-collinear
/// pairs, bias or thermal); and a "set aside:" note listing the stand-ins beyond the band that
/// the data preferred. Empty without ties.
std::vector<std::string> TieNotes(const Candidate& leader, const std::vector<Tie>& ties, bool has_logged_ambient,
                                  double tie_score);

}  // namespace rlg::diagnosis
