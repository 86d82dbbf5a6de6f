#pragma once
/// The reports of a population suite (population_suite.h): text, JSON, the checks as Check
/// records (so SuiteJunitXml writes them as JUnit), and the per-gyro CSV.
///
/// JSON (`validate --json` on a population suite; the Python module's population_summary):
///   {"population": {"suite", "gyro", "gyros", "seed",
///                   "parameters": [{"name", "nominal"}, ..],
///                   "metrics": [{"run", "compensator", "metric", "median", "p95", "worst",
///                                "worst_gyro", "median_interval", "p95_interval"}, ..],
///                   "checks": [{"check", "run", "compensator", "failed_gyros", "allowed",
///                               "passed", "worst_gyro", "worst_value", "worst_limit", "unit",
///                               "detail"}, ..],
///                   "yield": {"passing_gyros", "gyros", "fraction", "min_yield" (null: none),
///                             "passed"}},
///    "passed": bool}
/// worst_value and worst_limit are absent for a check without a number (best pair); the
/// intervals are [lo, hi], distribution-free 95 % (null: a side too few gyros bound).
///
/// Per-gyro CSV (`validate --gyros FILE`): one header row, then one row per gyro in index order:
///   gyro,seed,<each spread parameter>,<each metric: run.metric or run.compensator.metric>,checks_failed
/// Numbers are the shortest decimals that read back to the same double, so a row is the gyro's
/// exact parameters: `validate --gyro i` re-simulates it alone.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "validation/population_suite.h"
#include "validation/suite.h"

namespace rlg::validation {

/// One Check per population check: value = gyros that failed, limit = gyros allowed to fail,
/// unit "gyros", and a detail naming the worst gyro with its value and limit.
/// With [checks] min_yield, one more Check last, "yield": value = gyros failing some check, limit
/// = gyros allowed to, floor((1 - min_yield) x gyros). A failing check's detail ends with the
/// command that reruns its worst gyro alone (RerunCommand).
std::vector<Check> PopulationChecks(const PopulationSuite& suite, const PopulationSummary& summary);

/// The yield: the fraction of the gyros that passed every check (0 without gyros).
double YieldFraction(const PopulationSummary& summary);

/// "rlgtherm validate SUITE --gyro I": gyro I alone, with its full one-gyro report.
std::string RerunCommand(const PopulationSuite& suite, uint64_t gyro);

nlohmann::json PopulationJson(const PopulationSuite& suite, const PopulationSummary& summary);

/// The text `validate` prints: the spread, every metric's distribution, the checks.
std::string PopulationText(const PopulationSuite& suite, const PopulationSummary& summary);

std::string PopulationCsvHeader(const PopulationSuite& suite);
std::string PopulationCsvRow(const GyroOutcome& gyro);

}  // namespace rlg::validation
