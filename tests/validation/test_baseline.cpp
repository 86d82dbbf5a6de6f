// Regressions against a baseline (validation/baseline.h): each metric against k sigma of the
// noise of its two measurements, on reports made here, so the thresholds are closed forms.

#include <gtest/gtest.h>

#include <cmath>

#include "sim/errors.h"
#include "validation/baseline.h"

namespace rlg::validation {
namespace {

using nlohmann::json;

/// A one-row validate --json: |bias after| b with B0 error e, the 1 s stability s over n blocks.
json Report(double bias, double b0_error, double stability, double blocks) {
  json row = {{"run", "r"},
              {"compensator", "eq2"},
              {"bias_after_dph", bias},
              {"b0_error_dph", b0_error},
              {"stability_after_dph", stability},
              {"stability_blocks", blocks},
              {"stability_100s_after_dph", 0.01},
              {"stability_100s_blocks", 72},
              {"peak_abs_100s_after_dph", 0.02},
              {"error_100s_dph", 0.006},
              {"trend_dph_per_C", 0.001},
              {"trend_stderr_dph_per_C", nullptr}};  // infinite: not compared
  return {{"table2", json::array({row})}};
}

const BaselineComparison& Find(const BaselineReport& r, const std::string& metric) {
  for (const auto& c : r.compared)
    if (c.metric == metric) return c;
  throw std::logic_error("no " + metric);
}

TEST(Baseline, AReportAgainstItselfHasNoRegression) {
  const json a = Report(0.004, 0.005, 0.06, 7201);
  const BaselineReport r = CompareWithBaseline(a, a, "old.json");
  EXPECT_TRUE(r.passed());
  EXPECT_EQ(r.compared.size(), 4u);  // bias, two stabilities, peak; the trend without a standard error is not
}

TEST(Baseline, BiasRegressesBeyondKSigmaOfTheTwoB0Errors) {
  // sigma = hypot(0.003, 0.004) = 0.005; k = 4: the limit is |old| + 0.02. A relative margin of
  // 1e-9 on each side stays clear of the rounding of hypot and the sums (~1e-17).
  const json old = Report(-0.01, 0.003, 0.06, 7201);
  const BaselineReport just_within = CompareWithBaseline(Report(0.03 * (1 - 1e-9), 0.004, 0.06, 7201), old, "o");
  const BaselineReport just_beyond = CompareWithBaseline(Report(0.03 * (1 + 1e-9), 0.004, 0.06, 7201), old, "o");
  EXPECT_NEAR(Find(just_within, "abs_bias_after_dph").limit, 0.03, 1e-15);
  EXPECT_FALSE(Find(just_within, "abs_bias_after_dph").regressed);
  EXPECT_TRUE(Find(just_beyond, "abs_bias_after_dph").regressed);
  EXPECT_FALSE(just_beyond.passed());
}

TEST(Baseline, StabilityRegressesBeyondItsSamplingError) {
  // n = 51 blocks: sigma = s / sqrt(2 x 50) = s / 10 for each. From s_old = 0.06 a new s
  // regresses when s - 0.06 > 4 hypot(0.006, s / 10), i.e. above s = 0.110185 (solved by
  // bisection); 0.1100 and 0.1104 lie 1.8e-4 on either side, far beyond rounding.
  const json old = Report(0.0, 0.005, 0.06, 51);
  EXPECT_FALSE(Find(CompareWithBaseline(Report(0.0, 0.005, 0.1100, 51), old, "o"), "stability_after_dph").regressed);
  EXPECT_TRUE(Find(CompareWithBaseline(Report(0.0, 0.005, 0.1104, 51), old, "o"), "stability_after_dph").regressed);
}

TEST(Baseline, ALostRunRegressesAndANewRunIsNoted) {
  json old = Report(0.0, 0.005, 0.06, 7201);
  json now = old;
  now["table2"][0]["run"] = "other";
  const BaselineReport r = CompareWithBaseline(now, old, "o");
  EXPECT_TRUE(Find(r, "compensated").regressed);
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_NE(r.notes[0].find("run other [eq2]: not in the baseline"), std::string::npos) << r.notes[0];
}

TEST(Baseline, PopulationMediansRegressWhenTheirIntervalsLieApart) {
  auto population = [](double lo, double hi, uint64_t passing) {
    json m = {{"run", "r"},          {"compensator", "eq2"},          {"metric", "abs_bias_after_dph"},
              {"median", (lo + hi) / 2}, {"p95", hi},                 {"median_interval", {lo, hi}},
              {"p95_interval", {hi, nullptr}}};
    return json{{"population", {{"metrics", json::array({m})}, {"yield", {{"gyros", 1000}, {"passing_gyros", passing}}}}}};
  };
  const json old = population(0.01, 0.02, 900);
  EXPECT_FALSE(Find(CompareWithBaseline(population(0.019, 0.03, 900), old, "o"), "median abs_bias_after_dph").regressed);
  EXPECT_TRUE(Find(CompareWithBaseline(population(0.021, 0.03, 900), old, "o"), "median abs_bias_after_dph").regressed);
  // The yield, k = 4 pooled binomial standard errors: 900 -> 840 of 1000 gyros falls by 0.06
  // with pooled 0.87 and se sqrt(0.87 x 0.13 x 2 / 1000) = 0.01504, 3.99 se: within; 900 -> 830,
  // 0.07 with se 0.01528, 4.58 se: beyond.
  EXPECT_FALSE(Find(CompareWithBaseline(population(0.01, 0.02, 840), old, "o"), "yield").regressed);
  EXPECT_TRUE(Find(CompareWithBaseline(population(0.01, 0.02, 830), old, "o"), "yield").regressed);
}

TEST(Baseline, RefusesABaselineOfTheOtherKind) {
  const json suite = Report(0.0, 0.005, 0.06, 7201);
  const json population = {{"population", {{"metrics", json::array()}}}};
  EXPECT_THROW(CompareWithBaseline(suite, population, "o"), InputError);
  EXPECT_THROW(ReadBaseline("/nonexistent/old.json"), InputError);
}

}  // namespace
}  // namespace rlg::validation
