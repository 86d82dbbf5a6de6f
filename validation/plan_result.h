#pragma once
/// What the calibration-protocol planner concludes (validation/plan.h): per candidate its screen,
/// the distributions of its gyros' scores and whether it meets the target; the recommendation,
/// and the verification's verdict. With the summaries they are made of:
///
///   median, p95 (numpy's linear percentile, as populations) and worst of per-gyro values (°/h),
///   and the 90 % distribution-free interval of the p95 from the order statistics
///   (validation/order_statistics.h);
///   meets: yes when the interval's upper end is at or below the target, no when its lower end
///   is above, undecided otherwise (more gyros would tell);
///   the Pareto front of (chamber hours, p95): the candidates no other beats on both (at least
///   as good on both, better on one);
///   the verdict of a predicted against a realised p95 interval: inconsistent when the two do
///   not overlap, consistent when they overlap and both are bounded on both sides, undecided
///   when they overlap but one is open (an interval open above overlaps any prediction under
///   its lower end: no evidence either way).

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

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

/// The distribution of per-gyro values (median, p95, worst, 90 % interval of the p95).
Distribution Summarize(const std::vector<double>& values);
/// The interval of the p95 as the text prints it: "[lo, hi]", 4 decimals, -inf or inf for an
/// open end.
std::string FormatInterval(const Distribution& d);

/// Indices of the candidates on the Pareto front of (hours, p95), among those given.
std::vector<size_t> ParetoFront(const std::vector<double>& hours, const std::vector<double>& p95);

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

/// The verification's verdict (above): consistent, inconsistent (no overlap) or undecided (an
/// open interval).
enum class Verdict { kConsistent, kInconsistent, kUndecided };
/// "consistent", "inconsistent" or "undecided": the JSON's verify verdict.
const char* VerdictName(Verdict verdict);
/// The verdict for a predicted and a realised p95 interval (nullopt: an open end).
Verdict VerifyVerdict(std::optional<double> predicted_lo, std::optional<double> predicted_hi,
                      std::optional<double> realised_lo, std::optional<double> realised_hi);

struct VerifyResult {
  uint64_t gyros = 0;
  uint64_t seed = 0;
  double realised_p95 = 0.0;
  std::optional<double> realised_lo, realised_hi;
  Verdict verdict = Verdict::kUndecided;
  /// The fewest gyros that bound the p95's 90 % interval on both sides (DrawsToBound).
  uint64_t gyros_needed = 0;
  bool consistent() const { return verdict == Verdict::kConsistent; }
};

struct PlanResult {
  std::vector<CandidateResult> candidates;  ///< in the plan's order
  std::optional<size_t> recommended;
  std::string reason;                        ///< why that one, or why none
  std::optional<VerifyResult> verify;
};

}  // namespace rlg::validation
