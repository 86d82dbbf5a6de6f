// Population suites (validation/population_suite.h): percentiles against numpy's definition,
// a summary independent of the order and thread count, gyro i alone equal to gyro i in the run.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "compensation/model_compensator.h"
#include "model/fit_model.h"
#include "sim/errors.h"
#include "tools/source_dir.h"
#include "validation/population_report.h"
#include "validation/population_suite.h"

namespace rlg::validation {

namespace {

const std::string kSmall = rlg::tools::SourcePath("tests/data/population/small.toml");

TEST(Percentile, IsNumpysLinearDefinition) {
  // np.percentile([4, 1, 3, 2], [50, 95, 0, 100]) = [2.5, 3.85, 1, 4]
  const std::vector<double> v = {4, 1, 3, 2};
  EXPECT_DOUBLE_EQ(Percentile(v, 0.5), 2.5);
  EXPECT_NEAR(Percentile(v, 0.95), 3.85, 1e-15);  // 3 + 0.85 x 1, one rounding
  EXPECT_DOUBLE_EQ(Percentile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(Percentile(v, 1.0), 4.0);
  EXPECT_DOUBLE_EQ(Percentile({7.0}, 0.95), 7.0);
  EXPECT_THROW(Percentile({}, 0.5), InputError);
}

class SmallPopulation : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { suite_ = new PopulationSuite(LoadSuite(kSmall)); }
  static void TearDownTestSuite() { delete suite_; }
  static PopulationSuite* suite_;
};
PopulationSuite* SmallPopulation::suite_ = nullptr;

std::vector<GyroOutcome> RunAll(const PopulationSuite& s, int threads) {
  std::vector<GyroOutcome> out;
  RunPopulation(s, 0, s.population().count(), threads, [&](const GyroOutcome& g) { out.push_back(g); });
  return out;
}

void ExpectSame(const GyroOutcome& a, const GyroOutcome& b) {
  EXPECT_EQ(a.index, b.index);
  EXPECT_EQ(a.seed, b.seed);
  EXPECT_EQ(a.parameters, b.parameters);
  EXPECT_EQ(a.metrics, b.metrics);  // bit for bit: the same computation on any thread
  EXPECT_EQ(a.check_passed, b.check_passed);
}

TEST_F(SmallPopulation, LayoutIsTheSuitesRunsAndChecks) {
  EXPECT_EQ(suite_->metrics().size(), 4u * 7u);  // four compensated runs, seven metrics each (Table 2's six and the peak)
  EXPECT_EQ(suite_->metrics().front().Column(), "fixed-20.abs_bias_before_dph");
  EXPECT_EQ(suite_->parameters().size(), 4u + 1u + 1u);
  EXPECT_EQ(suite_->parameters().back(), "sensors.T1.offset_C");
}

TEST_F(SmallPopulation, OutcomesDoNotDependOnTheThreadCountAndComeInIndexOrder) {
  const auto one = RunAll(*suite_, 1);
  const auto two = RunAll(*suite_, 2);
  const auto three = RunAll(*suite_, 3);
  ASSERT_EQ(one.size(), 24u);
  ASSERT_EQ(two.size(), 24u);
  ASSERT_EQ(three.size(), 24u);
  for (size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].index, i);
    ExpectSame(one[i], two[i]);
    ExpectSame(one[i], three[i]);
  }
}

TEST_F(SmallPopulation, GyroAloneIsTheGyroInTheRun) {
  std::vector<GyroOutcome> some;
  RunPopulation(*suite_, 5, 3, 2, [&](const GyroOutcome& g) { some.push_back(g); });
  ASSERT_EQ(some.size(), 3u);
  EXPECT_EQ(some[0].index, 5u);
  ExpectSame(some[2], suite_->Run(7));
  sim::Population::Gyro drawn;
  const SuiteReport rep = suite_->Report(7, &drawn);
  EXPECT_EQ(drawn.values, some[2].parameters);
  ASSERT_EQ(rep.evaluations.size(), 4u);
  EXPECT_EQ(std::abs(rep.evaluations[3].bias_after_dph), some[2].metrics[3 * 7 + 1]);
  EXPECT_EQ(rep.evaluations[3].stability_100s_after.sigma, some[2].metrics[3 * 7 + 5]);
  EXPECT_EQ(rep.pairs.size(), 6u);  // the full report shows Table 1; Run keeps no pairs (no best_pair check)
  EXPECT_THROW(RunPopulation(*suite_, 20, 5, 1, [](const GyroOutcome&) {}), InputError);  // 20..24 of 24
}

TEST_F(SmallPopulation, RecycledRunsLendTheirBuffersAndChangeNoBit) {
  const GyroOutcome fresh = suite_->Run(3);
  std::vector<sim::Run> recycled;
  ExpectSame(suite_->Run(9, &recycled), suite_->Run(9));  // nothing to lend yet
  const size_t runs = recycled.size();
  ASSERT_GT(runs, 1u);  // gyro 9's runs, held for the next gyro
  // A lent buffer keeps its capacity; one allocated afresh would have the run's length (its
  // address alone could be the freed buffer's again).
  recycled.front().t_s.reserve(2 * recycled.front().size());
  recycled.back().columns.back().reserve(2 * recycled.back().size());
  const size_t t_capacity = recycled.front().t_s.capacity(), bias_capacity = recycled.back().columns.back().capacity();
  ExpectSame(suite_->Run(3, &recycled), fresh);  // gyro 9's values overwritten, none left over
  EXPECT_EQ(recycled.front().t_s.capacity(), t_capacity);  // lent, not allocated afresh
  EXPECT_EQ(recycled.back().columns.back().capacity(), bias_capacity);
  // Runs unlike the suite's: every value NaN, a run too short, one with a column more and stale
  // labels, and a run more than the suite has. RunSuite's trace is then the fresh one, field by
  // field and bit for bit (NaN != NaN: a value left over fails).
  std::vector<sim::Run> odd = recycled;
  for (auto& run : odd) {
    std::fill(run.t_s.begin(), run.t_s.end(), std::nan(""));
    for (auto& column : run.columns) std::fill(column.begin(), column.end(), std::nan(""));
  }
  odd.front().t_s.resize(10);
  odd[1].AddColumn("P_heater_W").assign(odd[1].size(), 7.0);
  odd[1].source = "stale.toml";
  odd[1].first_line = 12;
  odd.push_back(odd.back());
  const std::vector<sim::Scenario> scenarios = LoadSuiteScenarios(suite_->spec());
  const sim::Population::Gyro g = suite_->population().Draw(suite_->seed(), 3);
  const auto simulate = [&](std::vector<sim::Run> lent) {
    return RunSuite(suite_->spec(), scenarios, &g.config, g.seed, nullptr, PairScoring::kWhenChecked,
                    ChannelsRead(suite_->spec()), std::move(lent));
  };
  const SuiteReport a = simulate({}), b = simulate(odd);
  ASSERT_EQ(a.trace.runs.size(), b.trace.runs.size());
  for (size_t i = 0; i < a.trace.runs.size(); ++i) {
    const sim::Run& x = a.trace.runs[i];
    const sim::Run& y = b.trace.runs[i];
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.source, y.source);
    EXPECT_EQ(x.first_line, y.first_line);
    EXPECT_EQ(x.t_s, y.t_s);
    EXPECT_EQ(x.names, y.names);
    EXPECT_EQ(x.columns, y.columns) << x.id;
  }
  ExpectSame(suite_->Run(3, &odd), fresh);
  EXPECT_EQ(odd.size(), runs);
}

TEST_F(SmallPopulation, AGyroSimulatesOnlyThePairItsSuiteReadsAndGivesTheFullTracesMetrics) {
  // Eq. (2) on T1 and T2 reads no other sensor: a population gyro makes those two channels only
  // (each channel's noise is its own substream), and every metric and check is the one a trace
  // with all four channels gives, bit for bit.
  EXPECT_EQ(ChannelsRead(suite_->spec()).only, (std::vector<std::string>{"T1", "T2"}));
  const std::vector<sim::Scenario> scenarios = LoadSuiteScenarios(suite_->spec());
  for (uint64_t i : {0u, 13u}) {
    const sim::Population::Gyro g = suite_->population().Draw(suite_->seed(), i);
    const SuiteReport all =
        RunSuite(suite_->spec(), scenarios, &g.config, g.seed, nullptr, PairScoring::kWhenChecked);
    const SuiteReport pair = RunSuite(suite_->spec(), scenarios, &g.config, g.seed, nullptr, PairScoring::kWhenChecked,
                                      ChannelsRead(suite_->spec()));
    ASSERT_TRUE(all.trace.runs.front().Has("T3"));
    EXPECT_FALSE(pair.trace.runs.front().Has("T3"));  // a channel fewer per sensor left out: the test can fail
    ASSERT_EQ(all.evaluations.size(), pair.evaluations.size());
    for (size_t e = 0; e < all.evaluations.size(); ++e) {
      const auto& a = all.evaluations[e];
      const auto& b = pair.evaluations[e];
      EXPECT_EQ(a.bias_after_dph, b.bias_after_dph) << "gyro " << i << ", run " << e;
      EXPECT_EQ(a.stability_100s_after.sigma, b.stability_100s_after.sigma);
      EXPECT_EQ(a.peak_abs_100s_after_dph, b.peak_abs_100s_after_dph);
      EXPECT_EQ(a.trend_dph_per_C, b.trend_dph_per_C);
      EXPECT_EQ(a.allan.adev, b.allan.adev);
    }
    const auto fitted = [](const SuiteReport& r) { return std::get<model::Guo2006Coefficients>(r.models.front()).A; };
    EXPECT_EQ(fitted(all), fitted(pair));
    ASSERT_EQ(all.checks.size(), pair.checks.size());
    for (size_t c = 0; c < all.checks.size(); ++c) EXPECT_EQ(all.checks[c].value, pair.checks[c].value);
  }
}

TEST(PopulationSuite, ReadsEveryChannelUnlessEveryFitIsEq2OnAPairAndNothingElseReadsThem) {
  SuiteSpec spec = LoadSuite(kSmall);
  spec.expected_best_pair = "M1";  // Table 1 scores all six pairs
  EXPECT_TRUE(ChannelsRead(spec).only.empty());
  spec = LoadSuite(kSmall);
  spec.fits.front().request.model = "poly";  // a polynomial may read any channel
  EXPECT_TRUE(ChannelsRead(spec).only.empty());
  spec = LoadSuite(kSmall);
  spec.fits.front().request.pair.reset();
  EXPECT_TRUE(ChannelsRead(spec).only.empty());
}

TEST(PopulationSuite, ABestPairCheckIsScoredForEveryGyro) {
  // A population gyro scores its sensor pairs only when a check reads them: with `best_pair`,
  // every gyro's outcome carries that check, and its verdict is the full report's.
  SuiteSpec spec = LoadSuite(kSmall);
  spec.expected_best_pair = "M1";
  spec.population->count = 3;
  const PopulationSuite suite(spec);
  ASSERT_EQ(suite.checks().back().name, "best pair");
  for (uint64_t i = 0; i < 3; ++i) {
    const GyroOutcome g = suite.Run(i);
    const SuiteReport rep = suite.Report(i);
    ASSERT_EQ(rep.checks.back().name, "best pair");
    EXPECT_EQ(g.check_passed.back(), rep.checks.back().passed) << "gyro " << i;
  }
}

TEST_F(SmallPopulation, SummaryIsTheSameInAnyOrderOfOutcomes) {
  const auto all = RunAll(*suite_, 1);
  PopulationSummary forward(*suite_), backward(*suite_);
  for (const auto& g : all) forward.Add(g);
  for (auto it = all.rbegin(); it != all.rend(); ++it) backward.Add(*it);
  EXPECT_EQ(PopulationJson(*suite_, forward).dump(), PopulationJson(*suite_, backward).dump());

  // The distribution of one metric, recomputed here from the outcomes.
  const size_t m = 3 * 7 + 1;  // fixed+40, |bias after|
  std::vector<double> v;
  for (const auto& g : all) v.push_back(g.metrics[m]);
  const auto dist = forward.Metrics()[m];
  const auto worst = std::max_element(v.begin(), v.end());
  EXPECT_EQ(dist.worst, *worst);
  EXPECT_EQ(dist.worst_gyro, static_cast<uint64_t>(worst - v.begin()));
  EXPECT_EQ(dist.median, Percentile(v, 0.5));
  std::sort(v.begin(), v.end());
  EXPECT_GE(dist.p95, v[21]);  // position 23 x 0.95 = 21.85: between the 22nd and 23rd values
  EXPECT_LE(dist.p95, v[22]);
}

TEST_F(SmallPopulation, ACheckPassesWhileNoMoreThanTheWrittenFractionFails) {
  const auto all = RunAll(*suite_, 1);
  PopulationSummary summary(*suite_);
  for (const auto& g : all) summary.Add(g);
  const auto checks = summary.Checks();
  for (size_t c = 0; c < checks.size(); ++c) {
    uint64_t failed = 0;
    for (const auto& g : all) failed += g.check_passed[c] ? 0 : 1;
    EXPECT_EQ(checks[c].failed, failed) << suite_->checks()[c].Label();
    EXPECT_EQ(checks[c].allowed, 2u);  // floor(0.1 x 24)
    EXPECT_EQ(checks[c].passed, failed <= 2u);
  }
}

TEST_F(SmallPopulation, TheYieldIsTheGyrosPassingEveryCheck) {
  const auto all = RunAll(*suite_, 1);
  PopulationSummary summary(*suite_);
  uint64_t passing = 0;
  for (const auto& g : all) {
    summary.Add(g);
    passing += g.checks_failed() == 0 ? 1 : 0;
  }
  EXPECT_EQ(summary.passing_gyros(), passing);
  EXPECT_TRUE(summary.yield_passed());  // small.toml writes no min_yield: reported, not checked
  // Below each check's own failing count: a gyro failing two checks is one gyro lost, and gyros
  // failing different checks add up.
  for (const auto& d : summary.Checks()) EXPECT_LE(passing, all.size() - d.failed);
  EXPECT_EQ(PopulationChecks(*suite_, summary).size(), suite_->checks().size());  // no yield check
}

TEST_F(SmallPopulation, ACheckWithoutANumberNamesNoWorstGyroWhenNoneFailed) {
  // The first check made number-less (as the best pair is) and passed by every gyro.
  PopulationSummary summary(*suite_);
  for (GyroOutcome g : RunAll(*suite_, 1)) {
    g.check_passed[0] = true;
    g.check_value[0] = g.check_limit[0] = std::nan("");
    summary.Add(g);
  }
  const std::string detail = PopulationChecks(*suite_, summary)[0].detail;
  EXPECT_EQ(detail.find("worst gyro"), std::string::npos) << detail;
  EXPECT_EQ(detail.find("failing gyro"), std::string::npos) << detail;
}

TEST_F(SmallPopulation, RefusesAGyroAddedTwiceOrOfAnotherLayout) {
  const GyroOutcome g = suite_->Run(0);
  PopulationSummary summary(*suite_);
  EXPECT_THROW(summary.Metrics(), InputError);  // no gyro yet
  summary.Add(g);
  summary.Add(g);
  EXPECT_THROW(summary.Metrics(), InputError);
  GyroOutcome short_one = g;
  short_one.metrics.pop_back();
  EXPECT_THROW(summary.Add(short_one), InputError);
  GyroOutcome nan = g;
  nan.metrics[0] = std::nan("");
  EXPECT_THROW(summary.Add(nan), NumericalError);
}

TEST(PopulationSuite, RefusesASuiteWithoutPopulation) {
  EXPECT_THROW(PopulationSuite(LoadSuite(rlg::tools::SourcePath("scenarios/paper-suite.toml"))), InputError);
}

/// Eq. (2) from outside the suite: fitted on the training runs it is given, as the suite's fit.
ExternalCompensator ExternalEq2(const std::string& name) {
  return {name, [](uint64_t, const std::vector<const sim::Run*>& training, const std::vector<const sim::Run*>& runs) {
            model::FitRequest request;
            request.model = "guo2006";
            request.pair = std::array<std::string, 2>{"T1", "T2"};
            const model::FittedModel fitted = model::FitModel(training, request);
            std::vector<std::vector<double>> out;
            for (const sim::Run* r : runs) out.push_back(compensation::CompensateRun(fitted, *r));
            return out;
          }};
}

TEST(ExternalCompensator, EqualToTheSuitesEq2GivesItsMetricsAndChecksExactly) {
  const PopulationSuite builtin(LoadSuite(kSmall)), with(LoadSuite(kSmall), ExternalEq2("mine"));
  const size_t m = builtin.metrics().size(), c = builtin.checks().size();
  ASSERT_EQ(with.metrics().size(), 2 * m);
  ASSERT_EQ(with.checks().size(), 2 * c);
  EXPECT_EQ(with.metrics()[m].Column(), "fixed-20.mine.abs_bias_before_dph");
  EXPECT_EQ(with.checks()[c].Label(), builtin.checks()[0].Label() + " [mine]");
  for (uint64_t i : {0, 7}) {
    const GyroOutcome a = builtin.Run(i), b = with.Run(i);
    // Exact: the same fit on the same runs and the same causal compensator, evaluated alike.
    EXPECT_EQ(std::vector<double>(b.metrics.begin(), b.metrics.begin() + static_cast<long>(m)), a.metrics);
    EXPECT_EQ(std::vector<double>(b.metrics.begin() + static_cast<long>(m), b.metrics.end()), a.metrics);
    EXPECT_EQ(std::vector<bool>(b.check_passed.begin() + static_cast<long>(c), b.check_passed.end()), a.check_passed);
  }
}

TEST(ExternalCompensator, IsGivenEachFitsTrainingRunsAndTheRunsItCompensates) {
  std::vector<std::string> seen;
  ExternalCompensator e{"mine", [&](uint64_t gyro, const std::vector<const sim::Run*>& training,
                                    const std::vector<const sim::Run*>& runs) {
                          seen.push_back(std::to_string(gyro) + ":");
                          for (const auto* r : training) seen.back() += r->id + ",";
                          seen.back() += "|";
                          std::vector<std::vector<double>> out;
                          for (const auto* r : runs) {
                            seen.back() += r->id + ",";
                            out.push_back(r->Column("bias_dph"));
                          }
                          return out;
                        }};
  const PopulationSuite s(LoadSuite(kSmall), e);
  EXPECT_TRUE(seen.empty());  // the layout is fixed without calling it
  s.Run(5);
  EXPECT_EQ(seen, (std::vector<std::string>{"5:fixed-20,fixed+0,fixed+20,|fixed-20,fixed+0,fixed+20,fixed+40,"}));
}

TEST(ExternalCompensator, RefusesATakenNameAndOutputOfTheWrongShapeOrValue) {
  EXPECT_THROW(PopulationSuite(LoadSuite(kSmall), ExternalEq2("eq2")), InputError);
  EXPECT_THROW(PopulationSuite(LoadSuite(kSmall), ExternalEq2("auto")), InputError);
  EXPECT_THROW(PopulationSuite(LoadSuite(kSmall), ExternalEq2("")), InputError);
  auto giving = [](std::function<void(std::vector<std::vector<double>>&)> spoil) {
    return ExternalCompensator{"bad", [spoil](uint64_t, const std::vector<const sim::Run*>&,
                                             const std::vector<const sim::Run*>& runs) {
                                 std::vector<std::vector<double>> out;
                                 for (const auto* r : runs) out.push_back(r->Column("bias_dph"));
                                 spoil(out);
                                 return out;
                               }};
  };
  auto message = [&](std::function<void(std::vector<std::vector<double>>&)> spoil) {
    try {
      PopulationSuite(LoadSuite(kSmall), giving(spoil)).Run(2);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  const std::string suite = kSmall + ": compensator 'bad' on gyro 2";
  EXPECT_EQ(message([](auto& out) { out.pop_back(); }), suite + ": 3 compensated runs for the 4 runs of fit 'fixed'");
  EXPECT_EQ(message([](auto& out) { out[1].pop_back(); }),
            suite + ", run 'fixed+0': 1200 values for its 1201 samples (one per sample expected)");
  EXPECT_EQ(message([](auto& out) { out[0][3] = NAN; }), suite + ", run 'fixed-20': value 3 (t_s = 3): nan, not a finite bias");
  const std::string huge = message([](auto& out) { out[0][0] = 1e8; });
  EXPECT_EQ(huge.rfind(suite + ", run 'fixed-20': value 0 (t_s = 0): bias 1e+08 °/h is beyond", 0), 0u) << huge;
  // A suite that only summarizes (no function) lays out the rows but runs no gyro.
  const PopulationSuite names_only(LoadSuite(kSmall), ExternalCompensator{"mine", {}});
  // 2 compensators x 4 runs x 7 metrics (|bias|, 1 s and 100 s stability, each before and after;
  // the peak 100 s mean after).
  EXPECT_EQ(names_only.metrics().size(), 2 * 4u * 7u);
  EXPECT_THROW(names_only.Run(0), std::logic_error);
}

}  // namespace
}  // namespace rlg::validation
