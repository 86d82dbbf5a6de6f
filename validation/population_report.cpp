#include "validation/population_report.h"

#include <cmath>
#include <fmt/format.h>

namespace rlg::validation {
namespace {

std::string Describe(const sim::Spread& s) {
  switch (s.kind) {
    case sim::Spread::Kind::kNormal:
      return s.sigma > 0.0 ? fmt::format("normal, sigma {:g}", s.sigma)
                           : fmt::format("normal, {:g} % relative", 100.0 * s.relative_sigma);
    case sim::Spread::Kind::kLogNormal:
      return fmt::format("log-normal, {:g} % relative", 100.0 * s.relative_sigma);
    case sim::Spread::Kind::kUniform:
      return fmt::format("uniform, nominal {:+g} ... {:+g}", s.lo, s.hi);
  }
  return "";
}

/// [lo, hi] with null for an unbounded side.
nlohmann::json Interval(const std::pair<std::optional<double>, std::optional<double>>& iv) {
  auto side = [](const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); };
  return nlohmann::json::array({side(iv.first), side(iv.second)});
}

std::string Number(double v) { return std::isnan(v) ? "" : fmt::format("{}", v); }

}  // namespace

std::string RerunCommand(const PopulationSuite& suite, uint64_t gyro) {
  return fmt::format("rlgtherm validate {} --gyro {}", suite.spec().path, gyro);
}

std::vector<Check> PopulationChecks(const PopulationSuite& suite, const PopulationSummary& summary) {
  std::vector<Check> out;
  const auto dist = summary.Checks();
  for (size_t c = 0; c < dist.size(); ++c) {
    const PopulationCheck& key = suite.checks()[c];
    const CheckDistribution& d = dist[c];
    Check ch;
    ch.name = key.name;
    ch.run = key.run;
    ch.compensator = key.compensator;
    ch.passed = d.passed;
    ch.value = static_cast<double>(d.failed);
    ch.limit = static_cast<double>(d.allowed);
    ch.unit = "gyros";
    // The gyro worth a look: the one nearest (or furthest beyond) its limit, or, for a check
    // without a number (best pair), the first that failed; none when no gyro failed it.
    std::string worst;
    if (!std::isnan(d.worst_value)) {
      // "its own limit": a limit can differ per gyro (bias_after_floor_sigma), so this is not
      // always the gyro with the largest value, which the metric table names.
      worst = fmt::format("; worst gyro {}: {:.4g} against its own limit {:.4g} {}", d.worst_gyro, d.worst_value,
                          d.worst_limit, key.unit);
    } else if (d.failed > 0) {
      worst = fmt::format("; first failing gyro {}", d.worst_gyro);
    }
    ch.detail = fmt::format("failed on {} of {} gyros, {} allowed (max_failing_fraction {:g}){}", d.failed,
                            summary.gyros(), d.allowed, suite.spec().max_failing_fraction, worst);
    if (!d.passed) ch.detail += fmt::format("; rerun it alone: {}", RerunCommand(suite, d.worst_gyro));
    out.push_back(std::move(ch));
  }
  if (const auto& min = suite.spec().min_yield) {
    // In the units of the other population checks: gyros failing some check against the
    // number allowed to, floor((1 - min_yield) x gyros).
    const uint64_t n = summary.gyros(), failing = n - summary.passing_gyros();
    Check ch;
    ch.name = "yield";
    ch.compensator = "population";
    ch.passed = summary.yield_passed();
    ch.value = static_cast<double>(failing);
    ch.limit = std::floor((1.0 - *min) * static_cast<double>(n) + 1e-9);
    ch.unit = "gyros";
    ch.detail = fmt::format("{} of {} gyros ({:.1f} %) pass every check, min_yield {:g} (at {}) needs at least {:.0f}; {} "
                            "fail some check, {:.0f} may",
                            summary.passing_gyros(), n, 100.0 * YieldFraction(summary), *min,
                            suite.spec().min_yield_where, static_cast<double>(n) - *ch.limit, failing, *ch.limit);
    out.push_back(std::move(ch));
  }
  return out;
}

double YieldFraction(const PopulationSummary& summary) {
  return summary.gyros() == 0 ? 0.0 : static_cast<double>(summary.passing_gyros()) / static_cast<double>(summary.gyros());
}

nlohmann::json PopulationJson(const PopulationSuite& suite, const PopulationSummary& summary) {
  nlohmann::json p;
  p["suite"] = suite.spec().path;
  p["gyro"] = suite.population().nominal().name;
  p["gyros"] = summary.gyros();
  p["seed"] = suite.seed();
  p["parameters"] = nlohmann::json::array();
  for (size_t k = 0; k < suite.parameters().size(); ++k) {
    p["parameters"].push_back({{"name", suite.parameters()[k]}, {"nominal", suite.population().nominal_values()[k]}});
  }
  p["metrics"] = nlohmann::json::array();
  const auto metrics = summary.Metrics();
  for (size_t m = 0; m < metrics.size(); ++m) {
    const PopulationMetric& key = suite.metrics()[m];
    p["metrics"].push_back({{"run", key.run},
                            {"compensator", key.compensator},
                            {"metric", key.metric},
                            {"median", metrics[m].median},
                            {"p95", metrics[m].p95},
                            {"worst", metrics[m].worst},
                            {"worst_gyro", metrics[m].worst_gyro},
                            {"median_interval", Interval(metrics[m].median_interval)},
                            {"p95_interval", Interval(metrics[m].p95_interval)}});
  }
  p["checks"] = nlohmann::json::array();
  const auto dist = summary.Checks();
  const auto checks = PopulationChecks(suite, summary);
  for (size_t c = 0; c < dist.size(); ++c) {
    nlohmann::json j = {{"check", checks[c].name},
                        {"run", checks[c].run},
                        {"compensator", checks[c].compensator},
                        {"failed_gyros", dist[c].failed},
                        {"allowed", dist[c].allowed},
                        {"passed", dist[c].passed},
                        {"worst_gyro", dist[c].worst_gyro},
                        {"detail", checks[c].detail}};
    if (!std::isnan(dist[c].worst_value)) {
      j["worst_value"] = dist[c].worst_value;
      j["worst_limit"] = dist[c].worst_limit;
      j["unit"] = suite.checks()[c].unit;
    }
    p["checks"].push_back(std::move(j));
  }
  if (checks.size() > dist.size()) {  // the yield check (min_yield)
    const Check& y = checks.back();
    p["checks"].push_back({{"check", y.name},
                           {"run", ""},
                           {"compensator", y.compensator},
                           {"failed_gyros", *y.value},
                           {"allowed", *y.limit},
                           {"passed", y.passed},
                           {"detail", y.detail}});
  }
  p["yield"] = {{"passing_gyros", summary.passing_gyros()},
                {"gyros", summary.gyros()},
                {"fraction", YieldFraction(summary)},
                {"min_yield", suite.spec().min_yield ? nlohmann::json(*suite.spec().min_yield) : nlohmann::json(nullptr)},
                {"passed", summary.yield_passed()}};
  return {{"population", p}, {"passed", summary.passed()}};
}

std::string PopulationText(const PopulationSuite& suite, const PopulationSummary& summary) {
  fmt::memory_buffer out;
  auto w = std::back_inserter(out);
  const auto& spec = suite.spec();
  fmt::format_to(w, "Population: {} gyros of '{}', suite seed {} (gyro i simulated with SplitMix64(seed, i))\n",
                 summary.gyros(), suite.population().nominal().name, suite.seed());
  fmt::format_to(w, "Part-to-part spread ({} parameters):\n", suite.parameters().size());
  for (const auto& s : spec.population->spreads) fmt::format_to(w, "  {:<48} {}\n", s.parameter, Describe(s));
  for (const auto& c : spec.population->correlations) {
    fmt::format_to(w, "  correlation {:+g}: {} and {}\n", c.coefficient, c.a, c.b);
  }
  fmt::format_to(w, "\nTable 2 over the population, °/h (|bias|; stability 1 sigma at the suite's averaging time and at 100 s)\n");
  fmt::format_to(w, "{:<14} {:<10} {:<26} {:>9} {:>9} {:>9} {:>7}\n", "run", "by", "metric", "median", "p95", "worst",
                 "gyro");
  const auto metrics = summary.Metrics();
  for (size_t m = 0; m < metrics.size(); ++m) {
    const PopulationMetric& key = suite.metrics()[m];
    fmt::format_to(w, "{:<14} {:<10} {:<26} {:>9.4f} {:>9.4f} {:>9.4f} {:>7}\n", key.run, key.compensator, key.metric,
                   metrics[m].median, metrics[m].p95, metrics[m].worst, metrics[m].worst_gyro);
  }
  fmt::format_to(w, "\nChecks over the population (each gyro's checks as in a one-gyro suite; a check passes while at "
                    "most max_failing_fraction {:g} of the gyros fail it, each check on its own)\n",
                 spec.max_failing_fraction);
  size_t failed = 0;
  const auto checks = PopulationChecks(suite, summary);
  for (size_t c = 0; c < checks.size(); ++c) {
    if (!checks[c].passed) ++failed;
    const std::string label = c < suite.checks().size() ? suite.checks()[c].Label() : checks[c].name;
    fmt::format_to(w, "  {:<4} {:<32} {}\n", checks[c].passed ? "ok" : "FAIL", label, checks[c].detail);
  }
  // The yield is not the checks' fractions: a gyro failing any check is a gyro lost.
  fmt::format_to(w, "Yield: {} of {} gyros ({:.1f} %) pass every check{}\n", summary.passing_gyros(), summary.gyros(),
                 100.0 * YieldFraction(summary),
                 spec.min_yield ? fmt::format(" (min_yield {:g})", *spec.min_yield)
                                : " (no min_yield: max_failing_fraction bounds each check alone, not the yield)");
  fmt::format_to(w, "{} gyros, {} checks, {} failed: {}\n", summary.gyros(), checks.size(), failed,
                 summary.passed() ? "PASSED" : "FAILED");
  return fmt::to_string(out);
}

std::string PopulationCsvHeader(const PopulationSuite& suite) {
  std::string h = "gyro,seed";
  for (const auto& p : suite.parameters()) h += "," + p;
  for (const auto& m : suite.metrics()) h += "," + m.Column();
  return h + ",checks_failed\n";
}

std::string PopulationCsvRow(const GyroOutcome& g) {
  fmt::memory_buffer out;
  auto w = std::back_inserter(out);
  fmt::format_to(w, "{},{}", g.index, g.seed);
  for (double v : g.parameters) fmt::format_to(w, ",{}", Number(v));
  for (double v : g.metrics) fmt::format_to(w, ",{}", Number(v));
  fmt::format_to(w, ",{}\n", g.checks_failed());
  return fmt::to_string(out);
}

}  // namespace rlg::validation
