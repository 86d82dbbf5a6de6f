#pragma once
/// A candidate cause of a search step: an effect of the catalog on a target, its fitted
/// parameters, its information-criterion score and its held-out RMS ratio (statistics/score.h), and what
/// kind of candidate it is.

#include <map>
#include <string>
#include <tuple>

namespace rlg::diagnosis {

/// What a candidate is, and how far its search took it. Only kThermal and kBias can be
/// significant (statistics/rank.h).
enum class CandidateKind {
  kThermal,          ///< a thermal or sensor effect refitted with every knob (network/thermal_search.h)
  kThermalScreened,  ///< screened only, not refitted: its score is the linearised gain less ln n
  kThermalNoEffect,  ///< refitted, but the effect itself moves the prediction by less than min_score
  kBias,             ///< a bias effect: a column of the linear bias fit (network/bias_search.h)
};

/// The report's name of a kind: "thermal", "thermal (screened)", "thermal (no effect)",
/// "bias".
const char* KindName(CandidateKind kind);

/// kThermal, kThermalScreened or kThermalNoEffect.
bool IsThermal(CandidateKind kind);

/// A cause on a target: what a search takes at most once (the target in canonical form,
/// CanonicalTarget, where the search compares names that may differ).
struct CauseTarget {
  std::string cause, target;
  bool operator<(const CauseTarget& o) const { return std::tie(cause, target) < std::tie(o.cause, o.target); }
};

struct Candidate {
  std::string cause;   ///< the effect's name ("thermal.missing_link")
  std::string target;  ///< as the effect lists it ("anode-cathode", "T1")
  std::map<std::string, double> parameters;  ///< the effect's reported parameters (their units)
  double score = 0.0;                        ///< information-criterion units
  double heldout_rms_ratio = 1.0;            ///< before / after: > 1 predicts unseen data better
  /// Held-out log-likelihood ratio (information units, statistics/score.h LogLikelihoodRatio;
  /// bias candidates on residuals prewhitened by each model's own noise model): > 0 predicts
  /// unseen data better. What acceptance asks.
  double heldout_gain = 0.0;
  CandidateKind kind = CandidateKind::kThermal;
  /// For a bias effect whose shape was searched on the data (a mode hop): where its term steps,
  /// as bias-node temperatures, which is what the data fix (empty otherwise).
  std::string shape_note;
};

}  // namespace rlg::diagnosis
