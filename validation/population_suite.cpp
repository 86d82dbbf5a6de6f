#include "validation/population_suite.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <limits>
#include <mutex>
#include <vector>

#include "sim/errors.h"
#include "sim/gyro_compare.h"
#include "sim/trace_limits.h"
#include "validation/order_statistics.h"
#include "validation/parallel.h"

namespace rlg::validation {

using compensation::RunEvaluation;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// The level of the metrics' quantile intervals: 95 %, each side missing with at most 2.5 %.
constexpr double kIntervalLevel = 0.95;

// The Table 2 metrics of one evaluation, in PopulationSuite::metrics() order.
constexpr const char* kMetricNames[] = {"abs_bias_before_dph",       "abs_bias_after_dph",      "stability_before_dph",
                                        "stability_after_dph",       "stability_100s_before_dph", "stability_100s_after_dph",
                                        "peak_abs_100s_after_dph"};

std::array<double, 7> MetricValues(const RunEvaluation& e) {
  return {std::abs(e.bias_before_dph),   std::abs(e.bias_after_dph),       e.stability_before.sigma,
          e.stability_after.sigma,       e.stability_100s_before.sigma,    e.stability_100s_after.sigma,
          e.peak_abs_100s_after_dph};
}

}  // namespace

std::string PopulationMetric::Column() const {
  return compensator == kEq2 ? fmt::format("{}.{}", run, metric) : fmt::format("{}.{}.{}", run, compensator, metric);
}

std::string PopulationCheck::Label() const {
  std::string s = run.empty() ? name : fmt::format("{} {}", name, run);
  if (compensator != kEq2) s += fmt::format(" [{}]", compensator);
  return s;
}

size_t GyroOutcome::checks_failed() const {
  return static_cast<size_t>(std::count(check_passed.begin(), check_passed.end(), false));
}

PopulationSuite::PopulationSuite(SuiteSpec spec, std::optional<ExternalCompensator> external)
    : spec_(std::move(spec)),
      external_(std::move(external)),
      scenarios_(LoadSuiteScenarios(spec_)),
      population_(spec_.population ? *spec_.population : throw InputError(fmt::format(
                                                                 "{}: not a population suite: it has no [population] table",
                                                                 spec_.path)),
                  scenarios_.front().gyro),
      seed_(spec_.seed.value_or(scenarios_.front().seed)) {
  for (size_t s = 1; s < scenarios_.size(); ++s) {
    const auto diff = sim::GyroDifference(scenarios_.front().gyro, scenarios_[s].gyro);
    if (!diff.empty()) {
      throw InputError(fmt::format("{}: a population suite simulates one gyro per part, but scenario {} names another "
                                   "gyro than {} ({})",
                                   spec_.path, scenarios_[s].path, scenarios_.front().path, diff));
    }
  }
  if (external_) {
    // Its columns and labels must not be taken for another compensator's.
    std::vector<std::string> taken(std::begin(kFittedCompensatorNames), std::end(kFittedCompensatorNames));
    for (const auto& p : spec_.compensators) taken.push_back(p.name);
    if (external_->name.empty() || std::find(taken.begin(), taken.end(), external_->name) != taken.end()) {
      throw InputError(fmt::format("{}: a compensator named '{}': expected a non-empty name other than a fitted "
                                   "model's or a plug-in's of the suite ({})",
                                   spec_.path, external_->name, fmt::join(taken, ", ")));
    }
  }
  const sim::Population::Gyro g0 = population_.Draw(seed_, 0);
  SuiteReport rep = RunSuite(spec_, scenarios_, &g0.config, g0.seed, nullptr, PairScoring::kWhenChecked);
  AddExternal(0, true, rep);
  for (size_t i = 0; i < rep.evaluations.size(); ++i) {
    for (const char* m : kMetricNames) metrics_.push_back({rep.evaluations[i].run, rep.evaluation_compensator[i], m});
  }
  for (const auto& c : rep.checks) checks_.push_back({c.name, c.run, c.compensator, c.unit});
}

SuiteReport PopulationSuite::RunGyro(const sim::Population::Gyro& g, PairScoring pairs,
                                     std::vector<sim::Run> recycled) const {
  // A gyro of the population pass (pairs scored only when checked) and no compensator from
  // outside, which may read any channel: only the channels the suite reads are simulated.
  const bool checks_only = pairs == PairScoring::kWhenChecked && !external_;
  SuiteReport rep;
  try {
    rep = RunSuite(spec_, scenarios_, &g.config, g.seed, nullptr, pairs,
                   checks_only ? ChannelsRead(spec_) : sim::SensorChannels{}, std::move(recycled));
  } catch (const InputError& e) {
    // Gyro 0 ran in the constructor, so the suite itself is sound: this gyro's draw is what the
    // suite refused (a simulated value beyond what a gyro gives). Which gyro, to look at alone.
    throw InputError(fmt::format("{}: gyro {} (`validate --gyro {}`): {}", spec_.path, g.index, g.index, e.what()));
  }
  AddExternal(g.index, false, rep);
  return rep;
}

void PopulationSuite::AddExternal(uint64_t gyro, bool layout_only, SuiteReport& rep) const {
  if (!external_) return;
  if (!layout_only && !external_->compensate) {
    throw std::logic_error(fmt::format("compensator '{}' has no function: this suite only summarizes", external_->name));
  }
  for (size_t f = 0; f < spec_.fits.size(); ++f) {
    const SuiteFit& fit = spec_.fits[f];
    const std::vector<const sim::Run*> runs = rep.trace.Select(fit.compensate_runs);
    std::vector<std::vector<double>> compensated;
    if (layout_only) {
      for (const sim::Run* r : runs) compensated.push_back(r->Column("bias_dph"));
    } else {
      compensated = external_->compensate(gyro, rep.trace.Select(fit.fit_runs), runs);
    }
    const std::string who = fmt::format("{}: compensator '{}' on gyro {}", spec_.path, external_->name, gyro);
    if (compensated.size() != runs.size()) {
      throw InputError(fmt::format("{}: {} compensated runs for the {} runs of fit '{}'", who, compensated.size(),
                                   runs.size(), fit.name));
    }
    for (size_t k = 0; k < runs.size(); ++k) {
      if (compensated[k].size() != runs[k]->size()) {
        throw InputError(fmt::format("{}, run '{}': {} values for its {} samples (one per sample expected)", who,
                                     runs[k]->id, compensated[k].size(), runs[k]->size()));
      }
      // What a tidy CSV's bias column may hold: a NaN or 1e8 °/h is a mistake of the compensator's,
      // not a metric.
      const sim::ValueRange range = sim::RangeOf("bias_dph", sim::TraceLimits{});
      for (size_t n = 0; n < compensated[k].size(); ++n) {
        const double v = compensated[k][n];
        const std::string why = std::isfinite(v) ? sim::RangeProblem(range, v) : fmt::format("{}, not a finite bias", v);
        if (!why.empty()) {
          throw InputError(fmt::format("{}, run '{}': value {} (t_s = {:g}): {}", who, runs[k]->id, n, runs[k]->t_s[n], why));
        }
      }
      AddCompensatedRun(spec_, f, *runs[k], external_->name, std::move(compensated[k]), rep);
    }
  }
}

SuiteReport PopulationSuite::Report(uint64_t i, sim::Population::Gyro* drawn) const {
  sim::Population::Gyro g = population_.Draw(seed_, i);
  SuiteReport rep = RunGyro(g, PairScoring::kAlways);
  if (drawn) *drawn = std::move(g);
  return rep;
}

GyroOutcome PopulationSuite::Run(uint64_t i, std::vector<sim::Run>* recycled) const {
  const sim::Population::Gyro g = population_.Draw(seed_, i);
  SuiteReport rep = RunGyro(g, PairScoring::kWhenChecked, recycled ? std::move(*recycled) : std::vector<sim::Run>{});
  GyroOutcome o = Reduce(g, rep);
  if (recycled) *recycled = std::move(rep.trace.runs);
  return o;
}

GyroOutcome PopulationSuite::Reduce(const sim::Population::Gyro& g, const SuiteReport& rep) const {
  GyroOutcome o;
  o.index = g.index;
  o.seed = g.seed;
  o.parameters = g.values;
  for (const auto& e : rep.evaluations) {
    for (double v : MetricValues(e)) o.metrics.push_back(v);
  }
  for (const auto& c : rep.checks) {
    o.check_passed.push_back(c.passed);
    o.check_value.push_back(c.value.value_or(kNaN));
    o.check_limit.push_back(c.limit.value_or(kNaN));
  }
  // The layout is the suite's: the same runs and checks for every gyro. A difference would be a
  // bug (a check that depends on the data), not a property of the gyro.
  if (o.metrics.size() != metrics_.size() || o.check_passed.size() != checks_.size()) {
    throw std::logic_error(fmt::format("gyro {} gave {} metrics and {} checks, gyro 0 {} and {}", g.index,
                                       o.metrics.size(), o.check_passed.size(), metrics_.size(), checks_.size()));
  }
  return o;
}

void RunPopulation(const PopulationSuite& suite, uint64_t first, uint64_t count, int threads,
                   const std::function<void(const GyroOutcome&)>& on_gyro) {
  if (count == 0) return;
  if (first > suite.population().count() || count > suite.population().count() - first) {
    throw InputError(fmt::format("{}: gyros {}..{} are not all in a population of {}", suite.spec().path, first,
                                 first + count - 1, suite.population().count()));
  }
  // The outcomes reach on_gyro in index order, at most PipelineTokens(threads) of them alive at
  // once (validation/parallel.h).
  // Runs that lend their buffers to the next gyros (PopulationSuite::Run): one gyro's for each
  // gyro under way at most, freed on return. A gyro's runs are then neither allocated nor
  // zeroed afresh: ~5 % of a paper population gyro's CPU.
  std::mutex pool_mutex;
  std::vector<std::vector<sim::Run>> pool;
  OrderedPipeline<GyroOutcome>(
      count, threads,
      [&](uint64_t k) {
        std::vector<sim::Run> recycled;
        {
          const std::lock_guard<std::mutex> lock(pool_mutex);
          if (!pool.empty()) {
            recycled = std::move(pool.back());
            pool.pop_back();
          }
        }
        GyroOutcome o = suite.Run(first + k, &recycled);
        const std::lock_guard<std::mutex> lock(pool_mutex);
        pool.push_back(std::move(recycled));
        return o;
      },
      [&](uint64_t, GyroOutcome&& o) { on_gyro(o); });
}

PopulationSummary::PopulationSummary(const PopulationSuite& suite)
    : suite_(suite),
      values_(suite.metrics().size()),
      checks_(suite.checks().size()),
      worst_ratio_(suite.checks().size(), -std::numeric_limits<double>::infinity()) {}

void PopulationSummary::Add(const GyroOutcome& g) {
  if (g.metrics.size() != values_.size() || g.check_passed.size() != checks_.size() ||
      g.check_value.size() != checks_.size() || g.check_limit.size() != checks_.size()) {
    throw InputError(fmt::format("gyro {}: {} metrics and {} checks, but this suite has {} and {}", g.index,
                                 g.metrics.size(), g.check_passed.size(), values_.size(), checks_.size()));
  }
  for (size_t m = 0; m < values_.size(); ++m) {
    if (!std::isfinite(g.metrics[m])) {
      throw NumericalError(fmt::format("gyro {}: {} is {}", g.index, suite_.metrics()[m].Column(), g.metrics[m]));
    }
  }
  ++gyros_;
  if (g.checks_failed() == 0) ++passing_;
  seen_.push_back(g.index);
  for (size_t m = 0; m < values_.size(); ++m) values_[m].push_back(g.metrics[m]);
  for (size_t c = 0; c < checks_.size(); ++c) {
    CheckDistribution& d = checks_[c];
    if (!g.check_passed[c]) ++d.failed;
    // The worst gyro: largest value / limit; without a number, a failure outranks a pass and
    // the lower index wins a tie, so the order outcomes arrive in does not matter.
    double ratio = g.check_value[c] / g.check_limit[c];
    if (std::isnan(ratio)) ratio = g.check_passed[c] ? 0.0 : 1.0;
    if (ratio > worst_ratio_[c] || (ratio == worst_ratio_[c] && g.index < d.worst_gyro)) {
      worst_ratio_[c] = ratio;
      d.worst_gyro = g.index;
      d.worst_value = g.check_value[c];
      d.worst_limit = g.check_limit[c];
    }
  }
}

double Percentile(std::vector<double> values, double q) {
  if (values.empty()) throw InputError("a percentile of no values");
  std::sort(values.begin(), values.end());
  const double h = (static_cast<double>(values.size()) - 1.0) * q;
  const auto lo = static_cast<size_t>(std::floor(h));
  const size_t hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (h - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

std::vector<MetricDistribution> PopulationSummary::Metrics() const {
  if (gyros_ == 0) throw InputError(fmt::format("{}: no gyro to summarize", suite_.spec().path));
  std::vector<uint64_t> sorted = seen_;
  std::sort(sorted.begin(), sorted.end());
  const auto repeat = std::adjacent_find(sorted.begin(), sorted.end());
  if (repeat != sorted.end()) throw InputError(fmt::format("gyro {} was added twice", *repeat));
  std::vector<MetricDistribution> out(values_.size());
  for (size_t m = 0; m < values_.size(); ++m) {
    out[m].median = Percentile(values_[m], 0.5);
    out[m].p95 = Percentile(values_[m], 0.95);
    out[m].median_interval = QuantileIntervalValues(values_[m], 0.5, kIntervalLevel);
    out[m].p95_interval = QuantileIntervalValues(values_[m], 0.95, kIntervalLevel);
    out[m].worst = -std::numeric_limits<double>::infinity();
    for (size_t k = 0; k < values_[m].size(); ++k) {
      const double v = values_[m][k];
      if (v > out[m].worst || (v == out[m].worst && seen_[k] < out[m].worst_gyro)) {
        out[m].worst = v;
        out[m].worst_gyro = seen_[k];
      }
    }
  }
  return out;
}

std::vector<CheckDistribution> PopulationSummary::Checks() const {
  std::vector<CheckDistribution> out = checks_;
  for (auto& d : out) {
    // The product can land a rounding below a whole number (0.29 x 100 = 28.999999999999996);
    // 1e-9 of a gyro lifts it back without admitting a fraction more than written.
    d.allowed = static_cast<uint64_t>(std::floor(suite_.spec().max_failing_fraction * static_cast<double>(gyros_) + 1e-9));
    d.passed = d.failed <= d.allowed;
  }
  return out;
}

bool PopulationSummary::yield_passed() const {
  const auto& min = suite_.spec().min_yield;
  // passing >= min x gyros, compared in whole gyros as `allowed` is (the same 1e-9 of a gyro).
  return !min || static_cast<double>(passing_) + 1e-9 >= *min * static_cast<double>(gyros_);
}

bool PopulationSummary::passed() const {
  const auto checks = Checks();
  return yield_passed() &&
         std::all_of(checks.begin(), checks.end(), [](const CheckDistribution& d) { return d.passed; });
}

}  // namespace rlg::validation
