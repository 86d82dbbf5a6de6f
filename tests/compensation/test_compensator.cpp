// The causal compensator, its streaming driver and the Table 2 evaluation.

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "compensation/compensator.h"
#include "compensation/evaluation.h"
#include "compensation/stream.h"
#include "io/csv.h"
#include "model/allan.h"
#include "sim/errors.h"
#include "sim/stats.h"

namespace rlg::compensation {
namespace {

model::Guo2006Coefficients Coefficients() {
  model::Guo2006Coefficients c;
  c.A << 0.01, 2e-4, 0.0,  //
      -0.004, 0.0, 1e-6,   //
      0.3, 2e-3, 0.0;
  c.t10_range_C = {-30.0, 50.0};
  return c;
}

/// Eq. (2) exactly: temperatures dwell over the B0 window, then move.
sim::Run ModelRun(const model::Guo2006Coefficients& c, double T0, double hours = 1.0, double dt_s = 1.0) {
  sim::Run r;
  r.id = "run";
  auto& Ti = r.AddColumn("T1");
  auto& Tj = r.AddColumn("T2");
  auto& b = r.AddColumn("bias_dph");
  for (double t = 0.0; t <= hours * 3600.0; t += dt_s) {
    const double s = std::max(0.0, t - 120.0);
    const double ti = T0 + 2.0 * (1.0 - std::exp(-s / 900.0));
    const double tj = ti + 0.8 * (1.0 - std::exp(-s / 300.0));
    r.t_s.push_back(t);
    Ti.push_back(ti);
    Tj.push_back(tj);
    b.push_back(0.9 + c.Predict(ti, tj, T0));
  }
  return r;
}

TEST(Compensator, RemovesAnExactModelToRoundOff) {
  const auto c = Coefficients();
  const sim::Run run = ModelRun(c, 12.0);
  const std::vector<double> out = CompensateRun(c, run);
  for (double v : out) EXPECT_NEAR(v, 0.0, 1e-12);  // O(1) values, a few operations: round-off
}

TEST(Compensator, CapturesTi0AtTheFirstSampleAndFreezesB0AfterTheWindow) {
  const auto c = Coefficients();
  Compensator comp(c);
  EXPECT_DOUBLE_EQ(comp.Update(0.0, 5.0, 5.0, 1.0), 0.0);  // the first sample is its own B0
  EXPECT_DOUBLE_EQ(comp.Ti0(), 5.0);
  comp.Update(1.0, 5.0, 5.0, 3.0);  // running mean over the window: 2.0
  EXPECT_DOUBLE_EQ(comp.B0(), 2.0);
  EXPECT_FALSE(comp.b0_frozen());
  comp.Update(120.0, 5.0, 5.0, 100.0);  // t = t0 + window: outside, B0 frozen at 2.0
  EXPECT_TRUE(comp.b0_frozen());
  EXPECT_DOUBLE_EQ(comp.B0(), 2.0);
  comp.Reset();
  comp.Update(500.0, 7.0, 7.0, 4.0);
  EXPECT_DOUBLE_EQ(comp.Ti0(), 7.0);
  EXPECT_DOUBLE_EQ(comp.B0(), 4.0);
}

TEST(Compensator, IsCausalFutureSamplesDoNotChangePastOutputs) {
  const auto c = Coefficients();
  sim::Run run = ModelRun(c, 0.0, 0.5);
  const std::vector<double> before = CompensateRun(c, run);
  const size_t k = 60;  // inside the B0 window, the hardest case for causality
  for (size_t i = k + 1; i < run.size(); ++i) {
    run.columns[2][i] += 5.0;  // bias
    run.columns[0][i] -= 3.0;  // T1
  }
  const std::vector<double> after = CompensateRun(c, run);
  for (size_t i = 0; i <= k; ++i) EXPECT_EQ(before[i], after[i]) << i;
  EXPECT_NE(before[k + 1], after[k + 1]);
}

TEST(Compensator, BatchEqualsStreamingBitForBit) {
  const auto c = Coefficients();
  const sim::Run run = ModelRun(c, -7.0);
  std::vector<double> streamed;
  Compensator comp(c);
  const auto& Ti = run.Column("T1");
  const auto& Tj = run.Column("T2");
  const auto& b = run.Column("bias_dph");
  for (size_t k = 0; k < run.size(); ++k) streamed.push_back(comp.Update(run.t_s[k], Ti[k], Tj[k], b[k] + 0.01 * std::sin(k)));
  sim::Run noisy = run;
  for (size_t k = 0; k < run.size(); ++k) noisy.columns[2][k] += 0.01 * std::sin(k);
  EXPECT_EQ(CompensateRun(c, noisy), streamed);
}

TEST(Evaluation, ReportsBeforeAfterAndAFlatTrendForAPerfectModel) {
  const auto c = Coefficients();
  sim::Run run = ModelRun(c, 20.0, 2.0);
  for (size_t k = 0; k < run.size(); ++k) run.columns[2][k] += 0.05 * std::sin(0.7 * static_cast<double>(k));
  const std::vector<double> comp = CompensateRun(c, run);
  const RunEvaluation e = EvaluateRun(run, comp, c, 1.0);
  EXPECT_GT(e.stability_before.sigma, e.stability_after.sigma);
  EXPECT_GT(e.stability_100s_before.sigma, 5 * e.stability_100s_after.sigma);  // the trend dominates before
  EXPECT_LT(std::abs(e.bias_after_dph), 0.01);
  EXPECT_LT(std::abs(e.trend_dph_per_C), 3 * e.trend_stderr_dph_per_C);
  EXPECT_FALSE(e.outside_fitted_range);
  EXPECT_TRUE(EvaluateRun(ModelRun(c, 60.0), CompensateRun(c, ModelRun(c, 60.0)), c).outside_fitted_range);
}

/// ModelRun with a deterministic wobble on the bias (no two blocks alike).
sim::Run WobblyRun(const model::Guo2006Coefficients& c, double hours, double dt_s) {
  sim::Run run = ModelRun(c, 20.0, hours, dt_s);
  for (size_t k = 0; k < run.size(); ++k) run.columns[2][k] += 0.05 * std::sin(0.7 * static_cast<double>(k));
  return run;
}

TEST(Evaluation, OnTenSecondDataTheDefaultOneSecondIsComputedAndReportedAtTenSeconds) {
  const auto c = Coefficients();
  const sim::Run run = WobblyRun(c, 2.0, 10.0);
  const std::vector<double> comp = CompensateRun(c, run);
  const RunEvaluation e = EvaluateRun(run, comp, c);  // default options: 1 s, not chosen by the user
  EXPECT_DOUBLE_EQ(e.sample_period_s, 10.0);
  EXPECT_DOUBLE_EQ(e.stability_after.averaging_s, 10.0);
  EXPECT_TRUE(e.stability_after.below_sample_period);
  EXPECT_DOUBLE_EQ(e.stability_100s_after.averaging_s, 100.0);
  EXPECT_FALSE(e.stability_100s_after.adjusted());
  // The same number as asking for 10 s: one sample.
  EXPECT_EQ(e.stability_after.sigma, EvaluateRun(run, comp, c, 10.0).stability_after.sigma);
  const nlohmann::json j = EvaluationJson(e);
  EXPECT_EQ(j["stability_averaging_s"], 10.0);
  EXPECT_EQ(j["stability_100s_averaging_s"], 100.0);
}

TEST(Evaluation, OnTenSecondDataAnAveragingAskedBelowTheSamplePeriodIsRefused) {
  const auto c = Coefficients();
  const sim::Run run = WobblyRun(c, 2.0, 10.0);
  const std::vector<double> comp = CompensateRun(c, run);
  EXPECT_THROW(EvaluateRun(run, comp, c, 1.0), InputError);
  // 20 s is two samples: a different number from 10 s, no longer "1 s equals 10 s".
  EXPECT_NE(EvaluateRun(run, comp, c, 20.0).stability_after.sigma, EvaluateRun(run, comp, c, 10.0).stability_after.sigma);
}

TEST(Evaluation, OnSixtySecondDataTheHundredSecondStabilityIsOverTwoSamples) {
  const auto c = Coefficients();
  const sim::Run run = WobblyRun(c, 2.0, 60.0);
  const RunEvaluation e = EvaluateRun(run, CompensateRun(c, run), c);
  EXPECT_DOUBLE_EQ(e.stability_100s_after.averaging_s, 120.0);
  EXPECT_EQ(e.stability_100s_after.samples_per_block, 2u);
  EXPECT_DOUBLE_EQ(e.stability_after.averaging_s, 60.0);
  EXPECT_EQ(EvaluationJson(e)["stability_100s_averaging_s"], 120.0);
}

TEST(Evaluation, IrregularSamplingUsesTheMedianStep) {
  const auto c = Coefficients();
  sim::Run run = WobblyRun(c, 2.0, 1.0);
  for (size_t k = run.size() / 2; k < run.size(); ++k) run.t_s[k] += 600.0;  // a 10 min gap mid-run
  const RunEvaluation e = EvaluateRun(run, CompensateRun(c, run), c, 1.0);
  // The mean step over the record would be ~1.08 s and make "1 s" one sample of 1.08 s.
  EXPECT_DOUBLE_EQ(e.sample_period_s, 1.0);
  EXPECT_EQ(e.stability_100s_after.samples_per_block, 100u);
  EXPECT_FALSE(e.stability_after.adjusted());
}

TEST(Evaluation, ReadsTheBiasColumnItIsGiven) {
  const auto c = Coefficients();
  sim::Run run = WobblyRun(c, 1.0, 1.0);
  run.AddColumn("my_dph") = run.Column("bias_dph");
  for (auto& v : run.columns[2]) v += 100.0;  // bias_dph now differs from my_dph
  EvaluationOptions o;
  o.bias_column = "my_dph";
  const RunEvaluation e = EvaluateRun(run, CompensateRun(c, run, "my_dph"), c, o);
  EXPECT_NEAR(e.bias_before_dph, sim::Mean(run.Column("my_dph")), 1e-12);  // a mean of O(1) values: round-off
  EXPECT_LT(std::abs(e.bias_after_dph), 0.01);  // my_dph is the exact model plus a zero-mean wobble
}

TEST(Evaluation, WithoutCoefficientsTheTrendChannelAndB0WindowComeFromTheOptions) {
  const auto c = Coefficients();
  const sim::Run run = WobblyRun(c, 2.0, 1.0);
  const std::vector<double> comp = CompensateRun(c, run);
  const RunEvaluation fitted = EvaluateRun(run, comp, c, 1.0);
  EvaluationOptions o;
  o.averaging_explicit = true;
  o.trend_channel = c.pair[0];
  o.b0_window_s = c.b0_window_s;
  const RunEvaluation unfitted = EvaluateCompensated(run, comp, o);
  // One code path: the same numbers to the bit (== on doubles on purpose).
  EXPECT_EQ(EvaluationJson(unfitted).dump(), EvaluationJson(fitted).dump());
  o.trend_channel = "T2";
  EXPECT_NE(EvaluateCompensated(run, comp, o).trend_dph_per_C, fitted.trend_dph_per_C);
  o.trend_channel = "T9";
  EXPECT_THROW(EvaluateCompensated(run, comp, o), InputError);
}

TEST(Evaluation, ReadsTheErrorsAtTheNearestOctaveOfTheWholeThreeClusterCurve) {
  // The evaluation computes only the octaves it uses; the errors are those of the whole curve
  // (3 clusters), the read-offs' curve that of 9: windows around the octaves of a 2 h run at
  // 1 s (512, 1024, 2048 s; 724 s ~ sqrt(512 x 1024) is where the nearest one changes) and
  // beyond its longest octave.
  const auto c = Coefficients();
  const sim::Run run = WobblyRun(c, 2.0, 1.0);
  const std::vector<double> comp = CompensateRun(c, run);
  const model::AllanCurve whole = model::OverlappingAllan(comp, 1.0, 3);
  auto nearest = [&](double tau) {
    size_t best = 0;
    for (size_t i = 0; i < whole.tau_s.size(); ++i)
      if (std::abs(std::log(whole.tau_s[i] / tau)) < std::abs(std::log(whole.tau_s[best] / tau))) best = i;
    return whole.adev[best];
  };
  for (const double window : {120.0, 700.0, 723.0, 725.0, 1024.0, 1500.0, 2048.0, 3000.0}) {
    EvaluationOptions o;
    o.b0_window_s = window;
    const RunEvaluation e = EvaluateCompensated(run, comp, o);
    EXPECT_EQ(e.b0_error_dph, nearest(window)) << window << " s";
    EXPECT_EQ(e.error_100s_dph, nearest(100.0)) << window << " s";
    EXPECT_EQ(e.allan.adev, model::WithMinClusters(whole, comp.size(), 9).adev) << window << " s";
  }
}

TEST(Evaluation, RefusesACompensatedColumnOfAnotherLength) {
  const auto c = Coefficients();
  const sim::Run run = WobblyRun(c, 1.0, 1.0);
  std::vector<double> comp = CompensateRun(c, run);
  comp.pop_back();
  EXPECT_THROW(EvaluateCompensated(run, comp), InputError);
}

TEST(Compensator, AddsTheCompensatedColumnAsTheCsvWritesIt) {
  const auto c = Coefficients();
  sim::Trace trace;
  trace.runs.push_back(WobblyRun(c, 1.0, 1.0));
  const std::vector<double> exact = CompensateRun(c, trace.runs[0]);
  EXPECT_EQ(AddCompensatedColumn(c, trace), "bias_comp_dph");
  const std::vector<double>& added = trace.runs[0].Column("bias_comp_dph");
  std::istringstream csv(io::FormatTraceCsv(trace));
  io::CsvReadOptions keep;
  keep.keep_columns = {"bias_comp_dph"};
  const sim::Trace back = io::ReadTraceCsv(csv, "mem.csv", keep).trace;
  const std::vector<double>& read = back.runs[0].Column("bias_comp_dph");
  ASSERT_EQ(added.size(), exact.size());
  bool rounded = false;
  for (size_t k = 0; k < added.size(); ++k) {
    EXPECT_NEAR(added[k], exact[k], 0.5e-6 + 1e-15);  // 6 decimals: half a unit of the last one, plus round-off
    EXPECT_EQ(added[k], read[k]);                     // what the file holds, to the bit
    rounded = rounded || added[k] != exact[k];
  }
  EXPECT_TRUE(rounded);
}

TEST(Compensator, NamesTheCompensatedColumnAfterTheBiasColumn) {
  EXPECT_EQ(CompensatedColumnName("bias_dph"), "bias_comp_dph");
  EXPECT_EQ(CompensatedColumnName("my_comp_dph"), "my_comp_comp_dph");
  EXPECT_EQ(CompensatedColumnName("gyro"), "gyro_comp");
}

TEST(Compensator, RefusesARunShorterThanTheB0Window) {
  const auto c = Coefficients();
  EXPECT_THROW(CompensateRun(c, ModelRun(c, 0.0, 100.0 / 3600.0)), InputError);
}

// ---- streaming (compensation/stream.h) against batch compensation of the same CSV ----

/// A warm-up of `minutes` at 10 s from T0: T1 rises, T2 follows, a third channel that the
/// compensation does not use rides along, and the bias wobbles so that B0's running mean moves.
sim::Run WarmUp(const std::string& id, double T0, double minutes, const std::string& bias_column) {
  sim::Run r;
  r.id = id;
  auto& T1 = r.AddColumn("T1");
  auto& T2 = r.AddColumn("T2");
  auto& T3 = r.AddColumn("T3");
  auto& b = r.AddColumn(bias_column);
  for (double t = 0.0; t <= minutes * 60.0; t += 10.0) {
    r.t_s.push_back(t);
    T1.push_back(T0 + 3.0 * (1.0 - std::exp(-t / 900.0)));
    T2.push_back(T1.back() + 0.5 * (1.0 - std::exp(-t / 300.0)));
    T3.push_back(T0 + 0.1);
    b.push_back(0.9 + 0.01 * std::sin(t / 50.0) + 0.002 * (T1.back() - T0));
  }
  return r;
}

std::string TraceCsv(const std::string& bias_column) {
  sim::Trace trace;
  trace.comments = {" gyro: SN-0042"};
  trace.runs = {WarmUp("cold", -5.0, 20.0, bias_column), WarmUp("warm", 25.0, 10.0, bias_column)};
  std::ostringstream out;
  io::WriteTraceCsv(trace, out);
  return out.str();
}

/// What `compensate -o` writes: the CSV read back, each run compensated by CompensateRun.
std::string BatchCsv(const std::string& csv, const std::string& bias_column) {
  std::istringstream in(csv);
  sim::Trace trace = io::ReadTraceCsv(in, "batch.csv", StreamReadOptions(bias_column)).trace;
  for (auto& run : trace.runs) {
    std::vector<double> comp = CompensateRun(Coefficients(), run, bias_column);
    run.AddColumn(CompensatedColumnName(bias_column)) = std::move(comp);
  }
  std::ostringstream out;
  io::WriteTraceCsv(trace, out);
  return out.str();
}

std::string StreamCsv(const std::string& csv, const StreamOptions& options, size_t* rows = nullptr) {
  std::istringstream in(csv);
  io::CsvRowReader reader(in, "stream.csv", StreamReadOptions(options.bias_column));
  std::ostringstream out;
  const size_t n = CompensateStream(Coefficients(), reader, out, options);
  if (rows) *rows = n;
  return out.str();
}

TEST(CompensateStream, WritesTheBytesOfBatchCompensation) {
  const std::string csv = TraceCsv("bias_dph");
  StreamOptions options;
  size_t calls = 0, rows = 0;
  options.after_row = [&] { ++calls; };
  const std::string stream = StreamCsv(csv, options, &rows);
  EXPECT_EQ(stream, BatchCsv(csv, "bias_dph"));
  EXPECT_EQ(rows, 121u + 61u);  // 20 and 10 minutes at 10 s, both ends included
  EXPECT_EQ(calls, rows);
  EXPECT_EQ(stream.rfind("# gyro: SN-0042\nrun,t_s,T1,T2,T3,bias_dph,bias_comp_dph\n", 0), 0u) << stream.substr(0, 200);
}

TEST(CompensateStream, CompensatesTheColumnItIsGiven) {
  const std::string csv = TraceCsv("gyro2_dph");
  StreamOptions options;
  options.bias_column = "gyro2_dph";
  const std::string stream = StreamCsv(csv, options);
  EXPECT_EQ(stream, BatchCsv(csv, "gyro2_dph"));
  EXPECT_NE(stream.find(",gyro2_dph,gyro2_comp_dph\n"), std::string::npos);
}

TEST(CompensateStream, RefusesInputWithoutRowsAsTheBatchReaderDoesAndWritesNothing) {
  std::istringstream in("# only a header\nrun,t_s,T1,T2,bias_dph\n");
  io::CsvRowReader reader(in, "empty.csv");
  std::ostringstream out;
  try {
    CompensateStream(Coefficients(), reader, out, {});
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "empty.csv:2: no data rows after the header");
  }
  EXPECT_TRUE(out.str().empty());
}

TEST(CompensateStream, RefusesDataWithoutThePairAndWritesNothing) {
  std::istringstream in("run,t_s,T1,T3,bias_dph\na,0,20,20,0.5\n");
  io::CsvRowReader reader(in, "no_t2.csv");
  std::ostringstream out;
  StreamOptions options;
  options.data_name = "no_t2.csv";
  try {
    CompensateStream(Coefficients(), reader, out, options);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "no_t2.csv: no column 'T2' (the coefficients use pair T1,T2)");
  }
  EXPECT_TRUE(out.str().empty());
}

}  // namespace
}  // namespace rlg::compensation
