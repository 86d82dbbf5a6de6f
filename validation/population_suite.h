#pragma once
/// A validation suite run on every gyro of a population (docs/results.md, Populations): each gyro i is drawn
/// from the suite's [population] (sim/population.h), simulated on the suite's scenarios, fitted
/// on its own calibration runs and compensated, as a production line would (RunSuite with gyro
/// i and its seed). What a gyro gives is reduced at once to numbers (GyroOutcome: its drawn
/// parameters, its Table 2 metrics, its checks' values and limits); its traces are dropped, so
/// memory stays flat in the number of gyros. PopulationSummary keeps one double per gyro and
/// metric (and the gyro's id) and reports each metric's distribution:
///
///   median, p95   numpy's default ("linear") percentile of the values: position (N - 1) q in
///                 the sorted values, interpolated between its neighbours
///   worst         the largest value and the gyro that gave it (the lowest index on a tie)
///
/// Bias metrics are reduced as magnitudes |bias| (a bias of -0.02 °/h is as bad as +0.02); their
/// names say so: abs_bias_before_dph, abs_bias_after_dph. The stability metrics are 1 sigma at
/// the suite's averaging time and at 100 s, as Table 2. A check passes for the population while
/// at most [checks] max_failing_fraction of the gyros fail it; its worst gyro is the one with the
/// largest value / limit (the first failing one for the best-pair check).
///
/// The summary does not depend on the order the outcomes are added in, so gyros may run on any
/// number of threads (RunPopulation) or machines (the Python module's shards, docs/python.md)
/// and give the same bytes.

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "sim/population.h"
#include "validation/suite.h"

namespace rlg::validation {

struct PopulationMetric {
  std::string run, compensator, metric;  ///< e.g. "fixed+60", "eq2", "abs_bias_after_dph"
  std::string Column() const;            ///< "fixed+60.abs_bias_after_dph" (eq2) or "run.compensator.metric"
};

struct PopulationCheck {
  std::string name, run, compensator, unit;
  std::string Label() const;  ///< "bias after fixed+60" (+ " [compensator]" for a plug-in)
};

/// One gyro's result, reduced to numbers in the layout of its PopulationSuite.
struct GyroOutcome {
  uint64_t index = 0;
  uint64_t seed = 0;
  std::vector<double> parameters;     ///< per PopulationSuite::parameters()
  std::vector<double> metrics;        ///< per PopulationSuite::metrics()
  std::vector<bool> check_passed;     ///< per PopulationSuite::checks()
  std::vector<double> check_value;    ///< NaN for a check without a number (best pair)
  std::vector<double> check_limit;
  size_t checks_failed() const;
};

/// A compensator from outside the suite file, run in-process on every gyro (the Python module's
/// population_gyros(..., compensator=fit)), so that it is calibrated per gyro as the fitted
/// models are: for each [[fits]] entry, `compensate` gets the gyro's index, that fit's training
/// runs (its `runs`) and the runs it compensates (its `compensate`), all of this gyro, and
/// returns their compensated bias (°/h): one vector per run, in that order, one value per
/// sample. Its rows join the fitted models' and plug-ins' under `name` (metric columns
/// "run.name.metric"), each run evaluated with its fit's model (trend channel, B0 window) and
/// checked against the same limits (AddCompensatedRun), after the suite's own rows. It is
/// called from the population's threads side by side, so it must be thread-safe.
struct ExternalCompensator {
  using Compensate = std::function<std::vector<std::vector<double>>(
      uint64_t gyro, const std::vector<const sim::Run*>& training, const std::vector<const sim::Run*>& runs)>;
  std::string name;
  /// Empty for a suite that only summarizes shards (the layout needs the name alone); running
  /// a gyro then is a logic_error.
  Compensate compensate;
};

class PopulationSuite {
 public:
  /// Loads the scenarios and resolves the spread against their gyro (every scenario of a
  /// population suite must name the same gyro: a gyro is one part). Runs gyro 0 once to fix the
  /// layout, so a suite that cannot run fails here, before any thread starts (an external
  /// compensator's rows are laid out without calling it). InputError for a suite without
  /// [population], or an external compensator named as a fitted model or a plug-in is.
  explicit PopulationSuite(SuiteSpec spec, std::optional<ExternalCompensator> external = std::nullopt);

  /// Gyro i: drawn, simulated, fitted, compensated and checked (its sensor pairs scored only
  /// for a `best_pair` check). Thread-safe (const, no shared state), and the same numbers on
  /// any thread, each thread with its own `recycled`: the runs it holds (a previous call's) lend
  /// their buffers to gyro i's, which it holds afterwards (the same numbers, without allocating
  /// and zeroing a gyro's runs afresh).
  GyroOutcome Run(uint64_t i, std::vector<sim::Run>* recycled = nullptr) const;
  /// Gyro i's full report (what `validate --gyro i` prints), with its drawn gyro.
  SuiteReport Report(uint64_t i, sim::Population::Gyro* drawn = nullptr) const;

  const SuiteSpec& spec() const { return spec_; }
  const sim::Population& population() const { return population_; }
  uint64_t seed() const { return seed_; }
  const std::vector<std::string>& parameters() const { return population_.parameters(); }
  const std::vector<PopulationMetric>& metrics() const { return metrics_; }
  const std::vector<PopulationCheck>& checks() const { return checks_; }

 private:
  GyroOutcome Reduce(const sim::Population::Gyro& g, const SuiteReport& rep) const;
  /// Gyro g's suite report, the external compensator's rows included.
  SuiteReport RunGyro(const sim::Population::Gyro& g, PairScoring pairs, std::vector<sim::Run> recycled = {}) const;
  /// The external compensator's rows added to `rep`; `layout_only`: each run's raw bias stands
  /// in for its output (gyro 0 fixes the layout without calling it).
  void AddExternal(uint64_t gyro, bool layout_only, SuiteReport& rep) const;
  SuiteSpec spec_;
  std::optional<ExternalCompensator> external_;
  std::vector<sim::Scenario> scenarios_;
  sim::Population population_;
  uint64_t seed_;
  std::vector<PopulationMetric> metrics_;
  std::vector<PopulationCheck> checks_;
};

/// Runs gyros first .. first + count - 1 on `threads` threads (0: one per core; OrderedPipeline)
/// and hands each outcome to `on_gyro` in index order, from one thread at a time. At most a
/// few gyros per thread are in flight. An error in any gyro stops the run and is rethrown.
void RunPopulation(const PopulationSuite& suite, uint64_t first, uint64_t count, int threads,
                   const std::function<void(const GyroOutcome&)>& on_gyro);

struct MetricDistribution {
  double median = 0.0, p95 = 0.0, worst = 0.0;
  uint64_t worst_gyro = 0;
  /// Distribution-free 95 % intervals of the median and the p95 (order_statistics.h; nullopt:
  /// a side too few gyros bound), what --baseline compares populations with.
  std::pair<std::optional<double>, std::optional<double>> median_interval, p95_interval;
};

struct CheckDistribution {
  uint64_t failed = 0;        ///< gyros that failed it
  uint64_t allowed = 0;       ///< floor(max_failing_fraction x gyros)
  bool passed = true;         ///< failed <= allowed
  uint64_t worst_gyro = 0;    ///< largest value / limit, or the first failing gyro
  double worst_value = 0.0;   ///< NaN without a number
  double worst_limit = 0.0;
};

/// Accumulates outcomes (any order) and gives each metric's and check's distribution.
class PopulationSummary {
 public:
  explicit PopulationSummary(const PopulationSuite& suite);
  /// InputError for an outcome of another layout or a gyro added twice.
  void Add(const GyroOutcome& g);
  uint64_t gyros() const { return gyros_; }
  /// Per PopulationSuite::metrics(); InputError when no gyro was added.
  std::vector<MetricDistribution> Metrics() const;
  std::vector<CheckDistribution> Checks() const;
  /// The yield: gyros that passed every check (GyroOutcome::checks_failed() == 0).
  uint64_t passing_gyros() const { return passing_; }
  /// Whether the yield meets [checks] min_yield (true without one).
  bool yield_passed() const;
  /// Each check's distribution passes, and the yield meets min_yield.
  bool passed() const;

 private:
  const PopulationSuite& suite_;
  uint64_t gyros_ = 0;
  uint64_t passing_ = 0;  // gyros that passed every check
  std::vector<std::vector<double>> values_;  // per metric, one per gyro (order added)
  std::vector<uint64_t> seen_;               // the gyro of each value (order added); a repeat is refused
  std::vector<CheckDistribution> checks_;
  std::vector<double> worst_ratio_;          // per check: worst value / limit so far (-inf: none)
};

/// numpy's default (linear) percentile, q in [0, 1], of values (not sorted in place).
double Percentile(std::vector<double> values, double q);

}  // namespace rlg::validation
