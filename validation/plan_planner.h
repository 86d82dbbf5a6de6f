#pragma once
/// The planner (validation/plan.h, docs/plan.md): draws gyro i, screens each candidate
/// (validation/plan_screen.h), runs gyros through the candidates the screen keeps, and concludes
/// from their outcomes: summaries, Pareto front, recommendation and the verification.
///
/// Gyro i is the population's gyro i, or the nominal gyro with seed GyroSeed(seed, i) when the
/// plan has no [population]; a run is simulated with gyro i's seed on the stream FNV-1a of its
/// conditions (calibration and service apart). A gyro's outcome under a candidate:
///
///   score = max_s |mean of the compensated bias in service run s|      (°/h)
///   stability = max_s sigma of the compensated bias' 100 s means       (°/h, 1 sigma)
///
/// and |bias after| per service run s.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "model/compensation_model.h"
#include "sim/population.h"
#include "validation/plan_result.h"
#include "validation/plan_spec.h"

namespace rlg::validation {

/// FNV-1a, 64 bit, of a string's bytes: a run's stream from its conditions, a plan file's digest.
uint64_t Fnv1a(const std::string& bytes);

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

}  // namespace rlg::validation
