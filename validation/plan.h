#pragma once
/// The calibration-protocol planner (`rlgtherm plan`, docs/plan.md): for each candidate protocol
/// of a plan (validation/plan_spec.h), every gyro is calibrated on the candidate's chamber runs,
/// fitted with the plan's model and compensated on the service conditions, as a production
/// line would, before any chamber is booked.
///
/// Gyro i is the population's gyro i (sim/population.h: drawn from the plan's seed and i), or
/// the nominal gyro with seed GyroSeed(seed, i) when the plan has no [population]. A run is
/// simulated with gyro i's seed on a stream made from its conditions (FNV-1a of
/// ChamberRun::Conditions, calibration and service apart): equal conditions give equal data,
/// so candidates sharing a soak see the same soak (common random numbers: differences between
/// candidates are differences of protocol, not of noise), and each gyro simulates each run once
/// for every candidate that uses it.
///
/// A gyro's score under a candidate is its worst service condition:
///
///   score_i = max_s |mean of the compensated bias in service run s|      (°/h)
///   stability_i = max_s sigma of the compensated bias' 100 s means      (°/h, 1 sigma)
///
/// and the candidate's predictions are over gyros: the median, the p95 (numpy's linear
/// percentile, as populations) and the worst score, the 90 % distribution-free interval of the
/// p95 from the order statistics (validation/order_statistics.h), the median and p95 of the
/// stability, and per service run the median and p95 of |bias after|. Chamber hours: the sum
/// over the candidate's runs of settling and run length (plan_spec.h).
///
/// A candidate meets the target when its interval's upper end is at or below it ("yes"), fails
/// it when the lower end is above ("no"), and is "undecided" otherwise (more gyros would tell).
/// The recommendation is the cheapest candidate that meets it (ties: lower p95, then name), or
/// none, with the reason. The Pareto front: the candidates no other beats on both chamber hours
/// and p95 (at least as good on both, better on one).
///
/// The analytic screen (validation/plan_screen.h) is computed first for every candidate, from
/// the nominal gyro without noise; [screen] keep = K simulates only the K candidates with the
/// smallest screened p95. A candidate the model cannot be fitted on (Eq. (2) on a single
/// power-on, which fixes T10) is reported with the fit's reason and no numbers.
///
/// --verify N: N further gyros, drawn from a seed derived from the plan's (VerifySeed: none of
/// them is a gyro of the prediction), through the recommended candidate; its realised p95 and
/// interval beside the predicted ones: inconsistent when the two intervals do not overlap,
/// consistent when they overlap and both are bounded on both sides, and undecided when they
/// overlap but one is open (fewer than 59 gyros leave the p95's open above, and an interval
/// open above overlaps any prediction under its lower end: no evidence either way).
///
/// Results do not depend on the number of threads: gyro i's numbers are computed alone and
/// stored at index i.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "model/compensation_model.h"
#include "sim/population.h"
#include "validation/plan_spec.h"

namespace rlg::validation {

/// The level of every interval the planner reports.
inline constexpr double kPlanIntervalLevel = 0.90;

struct ScreenResult {
  std::string failure;            ///< why the nominal fit failed; empty when it did not
  std::vector<double> bias_dph;   ///< m_s per service run
  std::vector<double> sd_dph;     ///< sqrt(v_s) per service run
  double median_dph = 0.0, p95_dph = 0.0;
};

struct Distribution {
  double median = 0.0, p95 = 0.0, worst = 0.0;
  uint64_t worst_gyro = 0;
  std::optional<double> p95_lo, p95_hi;  ///< the 90 % interval of the p95; none: unbounded
};

/// Whether a candidate meets the target, by its p95 interval (above): yes, no or undecided.
enum class Meets { kYes, kNo, kUndecided };
/// "yes", "no" or "undecided": the JSON's meets_target and the text's "meets target" column.
const char* MeetsName(Meets meets);

struct CandidateResult {
  std::string name;
  std::string model;        ///< the fitted model's name
  double chamber_h = 0.0;
  ScreenResult screen;
  bool simulated = false;   ///< kept by the screen (and fittable)
  std::string failure;      ///< the first gyro whose fit failed, and why; empty when none
  Distribution abs_bias_after;
  Distribution stability_100s;
  std::vector<Distribution> service;  ///< |bias after| per service run
  std::optional<Meets> meets;  ///< nullopt when not simulated or failed
  bool pareto = false;
  bool has_numbers() const { return simulated && failure.empty(); }
};

struct VerifyResult {
  uint64_t gyros = 0;
  uint64_t seed = 0;
  double realised_p95 = 0.0;
  std::optional<double> realised_lo, realised_hi;
  bool consistent = false;  ///< verdict == "consistent"
  std::string verdict;      ///< "consistent", "inconsistent" (no overlap) or "undecided" (an open interval)
  /// The fewest gyros that bound the p95's 90 % interval on both sides (DrawsToBound).
  uint64_t gyros_needed = 0;
};

/// The verdict above for a predicted and a realised p95 interval (nullopt: an open end).
std::string VerifyVerdict(std::optional<double> predicted_lo, std::optional<double> predicted_hi,
                          std::optional<double> realised_lo, std::optional<double> realised_hi);

struct PlanResult {
  std::vector<CandidateResult> candidates;  ///< in the plan's order
  std::optional<size_t> recommended;
  std::string reason;                        ///< why that one, or why none
  std::optional<VerifyResult> verify;
};

/// One gyro under the candidates asked for: score and stability, and |bias after| per service
/// run; `failure` holds the fit's message when the candidate could not be fitted on this gyro.
struct GyroCandidateOutcome {
  double score = 0.0, stability = 0.0;
  std::vector<double> service_abs_bias;
  std::string failure;
};

/// The screen of every candidate and the outcomes of gyros first .. first + count - 1 under the
/// candidates it keeps: a whole plan (first 0, count gyros) or one shard of it.
struct PlanShard {
  uint64_t first = 0, count = 0;
  std::vector<ScreenResult> screens;  ///< per candidate of the plan
  std::vector<size_t> kept;           ///< the candidates simulated
  std::vector<std::vector<GyroCandidateOutcome>> outcomes;  ///< [kept slot][gyro - first]
};

class Planner {
 public:
  /// Resolves the population against the gyro (InputError as in validate) and checks the spec.
  explicit Planner(PlanSpec spec);

  const PlanSpec& spec() const { return spec_; }
  /// The model a candidate fits.
  const model::FitRequest& ModelOf(size_t candidate) const;

  /// The analytic screen of candidate c (plan_screen.h).
  ScreenResult Screen(size_t candidate) const;
  /// The model the screen of candidate c fits on the noise-free runs: ModelOf(c), or for auto
  /// the polynomial auto selects on the nominal gyro's calibration runs with their noise (the
  /// selection needs noise: on noise-free runs every term helps).
  model::FitRequest ScreenedModel(size_t candidate) const;

  /// Gyro i of the population drawn with `suite_seed` through candidates `which` (indices).
  std::vector<GyroCandidateOutcome> RunGyro(uint64_t suite_seed, uint64_t i, const std::vector<size_t>& which) const;

  /// Everything: screen, Monte Carlo on `threads` threads (0: one per core), summaries,
  /// recommendation, and with verify > 0 the verification: Conclude(Simulate(0, gyros)).
  /// `between_gyros`, when given, is called before each gyro, from the thread that runs it; an
  /// exception it throws stops the gyros (those under way finish) and is rethrown (the Python
  /// module's Ctrl-C).
  PlanResult Run(int threads, uint64_t verify = 0, const std::function<void()>& between_gyros = {}) const;
  /// The screen and gyros first .. first + count - 1 through the candidates it keeps.
  PlanShard Simulate(uint64_t first, uint64_t count, int threads, const std::function<void()>& between_gyros = {}) const;
  /// Summaries, front and answer from the outcomes of every gyro (InputError otherwise).
  PlanResult Conclude(const PlanShard& all, int threads, uint64_t verify = 0,
                      const std::function<void()>& between_gyros = {}) const;

  /// The seed the verification draws its gyros from.
  uint64_t VerifySeed() const;

 private:
  sim::Population::Gyro Draw(uint64_t suite_seed, uint64_t i) const;
  PlanSpec spec_;
  std::optional<sim::Population> population_;
};

/// Runs gyros first .. first + n - 1 (seeded with suite_seed) through `which` on `threads` threads
/// with oneTBB and returns outcome[candidate slot][gyro - first]; between_gyros as in Planner::Run.
std::vector<std::vector<GyroCandidateOutcome>> RunGyros(const Planner& planner, uint64_t suite_seed, uint64_t first,
                                                        uint64_t n, const std::vector<size_t>& which, int threads,
                                                        const std::function<void()>& between_gyros = {});

/// A shard for machines apart (`plan --gyros FROM:TO --json`, docs/plan.md): the plan file's
/// digest (FNV-1a of its bytes) and seed, the gyro range, and per simulated candidate each gyro's
/// score, stability, |bias after| per service run and fit failure; doubles as JSON writes them
/// (shortest round trip), so a merge reads back the same bits.
nlohmann::json ShardJson(const Planner& planner, const PlanShard& shard);
/// The shards of one plan merged (`plan --merge SHARD.json..`): InputError naming the file for a
/// shard of another plan file or seed, a gyro in two shards or in none, or a malformed shard.
/// Conclude on the result gives the bytes of the plan run in one piece.
PlanShard MergeShards(const Planner& planner, const std::vector<std::pair<std::string, nlohmann::json>>& shards);

/// The distribution of per-gyro values (median, p95, worst, 90 % interval of the p95).
Distribution Summarize(const std::vector<double>& values);

/// Indices of the candidates on the Pareto front of (hours, p95), among those given.
std::vector<size_t> ParetoFront(const std::vector<double>& hours, const std::vector<double>& p95);

/// `plan --json` (docs/plan.md) and the text report: a table, then a one-line answer.
nlohmann::json PlanJson(const Planner& planner, const PlanResult& r);
std::string PlanText(const Planner& planner, const PlanResult& r);
/// The one-line answer both end with: "answer: NAME (H chamber h): p95 ... REASON" or
/// "answer: none: REASON".
std::string PlanAnswer(const PlanResult& r);

}  // namespace rlg::validation
