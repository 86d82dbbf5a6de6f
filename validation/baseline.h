#pragma once
/// Regression against a baseline (`validate SUITE --baseline OLD.json`): each metric of this
/// report's `--json` compared with the same metric of a previous `--json` of the suite, against
/// the noise of the two measurements, so that a change of the code, the model or the gyro that
/// makes a metric worse beyond its noise fails the gate (exit 4) naming the metric, the run and
/// by how much, while a rerun with other noise passes.
///
/// One-gyro suites: per compensated run and compensator (table2's rows), a metric regressed when
///   new - old > k sqrt(sigma_old² + sigma_new²)
/// with k = [checks] baseline_max_sigma (default kBaselineMaxSigma) and each measurement's 1 sigma:
///   |bias after|         b0_error_dph: the error of the B0 window mean, which bias after carries
///                        (the run mean itself is hours long, its own error far smaller)
///   stability (1 s, 100 s) s / sqrt(2 (n - 1)), the sampling error of the standard deviation s
///                        of n block means (stability_blocks); exact for independent Gaussian
///                        blocks, an underestimate where the blocks are correlated (slow drift)
///   peak 100s            sqrt(b0_error² + error_100s²): one 100 s mean (its Allan deviation at
///                        ~100 s) offset by the B0 window's error, both in every 100 s mean
///   |trend|              trend_stderr_dph_per_C (its AR(1)-widened standard error; not compared
///                        where it is infinite: no temperature change)
/// The magnitudes |bias after| and |trend| are compared as their sign carries no quality. A run
/// of the baseline no longer compensated regresses too (a gate must not lose runs silently); a
/// new run is noted, compared from the next baseline on.
///
/// Population suites: per metric after compensation (|bias after|, both stabilities, the peak),
/// its median and p95 regressed when their distribution-free 95 % intervals (order statistics,
/// validation/order_statistics.h) do not overlap, the new one above: each side of an interval
/// misses its quantile with at most 2.5 %, so two gyro populations of the same design disagree
/// so far by chance in well under 2.5 % of comparisons. An interval unbounded for the number of
/// gyros (p95 below 59 gyros) is not compared, and says so. The yield (gyros passing every check)
/// regressed when it fell by more than k pooled binomial standard errors,
/// sqrt(y (1 - y) (1 / n_old + 1 / n_new)) with y the pooled yield.
///
/// The comparison reads both reports as JSON (the current one as `--json` prints it), so a
/// baseline is any earlier `--json` output; one of the other kind (a population's for a one-gyro
/// suite, or no validate report at all) is an InputError naming the file.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "validation/suite.h"

namespace rlg::validation {

/// k of the regression test: one-sided Gaussian tail 3.2e-5 per metric, so that a suite of ~100
/// compared metrics raises a false alarm on fresh noise (another seed) in ~0.3 % of comparisons.
inline constexpr double kBaselineMaxSigma = 4.0;

struct BaselineComparison {
  std::string metric;       ///< "abs_bias_after_dph", "stability_100s_after_dph", "median abs_bias_after_dph", "yield", ..
  std::string run;          ///< empty for suite-wide metrics (the yield)
  std::string compensator;  ///< "eq2", a model's or a plug-in's name; "population" for the yield
  double old_value = 0.0, new_value = 0.0;
  double limit = 0.0;  ///< the largest new value that is not a regression (the smallest yield)
  bool regressed = false;
  std::string unit;    ///< of the values: "°/h", "°/h/°C", "gyros"
  std::string detail;  ///< old -> new, the change, the noise it is compared with
};

struct BaselineReport {
  std::string file;
  double max_sigma = kBaselineMaxSigma;
  std::vector<BaselineComparison> compared;  ///< in the current report's order; the regressions among them
  std::vector<std::string> notes;            ///< what was not compared, and why
  bool passed() const;
  size_t regressions() const;
};

/// Reads OLD.json (InputError naming the file for one that cannot be read or is not a validate
/// report).
nlohmann::json ReadBaseline(const std::string& path);

/// `current` and `baseline` as `validate --json` prints them (one-gyro or population suites).
BaselineReport CompareWithBaseline(const nlohmann::json& current, const nlohmann::json& baseline,
                                   const std::string& file, double max_sigma = kBaselineMaxSigma);

/// The "baseline" object of `--json`: {"file", "max_sigma", "compared": [{"metric", "run",
/// "compensator", "old", "new", "limit", "unit", "regressed", "detail"}, ..], "regressed": n,
/// "notes": [..], "passed"}.
nlohmann::json BaselineJson(const BaselineReport& report);

/// Each comparison as a Check "baseline METRIC" (value the new value, limit the largest that is
/// not a regression: the smallest for the yield), for the JUnit file.
std::vector<Check> BaselineChecks(const BaselineReport& report);

/// The text section: the count, each regression, the notes.
std::string BaselineText(const BaselineReport& report);

}  // namespace rlg::validation
