// Fitting, compensation and Allan throughput.
//   build/bin/rlg_bench_model
// BM_JointFit:              Eq. (2) joint fit of 10 runs x 7,200 samples (issue target < 5 ms)
// BM_StreamingCompensation: Compensator::Update per sample (target >= 10 M samples/s)
// BM_Allan24h100Hz:         overlapping Allan deviation + read-offs of 24 h at 100 Hz (target << 1 s)

#include <benchmark/benchmark.h>

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>

#include "compensation/compensator.h"
#include "model/allan.h"
#include "model/guo2006.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace {

using namespace rlg;

const sim::Trace& PaperFixed() {
  static const sim::Trace trace = [] {
    const sim::Scenario sc = sim::LoadScenario(std::string(RLG_SOURCE_DIR) + "/scenarios/paper-fixed.toml");
    return sim::SimulateScenario(sc, sc.seed);
  }();
  return trace;
}

void BM_JointFit(benchmark::State& state) {
  std::vector<const sim::Run*> runs;
  for (const auto& r : PaperFixed().runs) runs.push_back(&r);  // 10 runs x 7,201 samples
  model::FitOptions o;
  for (auto _ : state) benchmark::DoNotOptimize(model::FitGuo2006(runs, o));
  state.SetItemsProcessed(state.iterations() * 10 * 7201);
}
BENCHMARK(BM_JointFit)->Unit(benchmark::kMillisecond);

void BM_StreamingCompensation(benchmark::State& state) {
  std::vector<const sim::Run*> runs;
  for (const auto& r : PaperFixed().runs) runs.push_back(&r);
  const model::Guo2006Coefficients c = model::FitGuo2006(runs, model::FitOptions{});
  const sim::Run& run = PaperFixed().runs[3];
  const auto& Ti = run.Column("T1");
  const auto& Tj = run.Column("T2");
  const auto& b = run.Column("bias_dph");
  compensation::Compensator comp(c);
  double sink = 0.0;
  for (auto _ : state) {
    comp.Reset();
    for (size_t k = 0; k < run.size(); ++k) sink += comp.Update(run.t_s[k], Ti[k], Tj[k], b[k]);
  }
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(run.size()));
}
BENCHMARK(BM_StreamingCompensation);

void BM_Allan24h100Hz(benchmark::State& state) {
  const size_t n = 24 * 3600 * 100;
  std::vector<double> y(n);
  boost::random::mt19937_64 rng(1);
  boost::random::normal_distribution<double> normal;
  for (auto& v : y) v = 0.6 * normal(rng);  // ARW 0.001 °/sqrt(h) at 100 Hz
  for (auto _ : state) {
    const model::AllanCurve curve = model::OverlappingAllan(y, 0.01);
    benchmark::DoNotOptimize(model::FitNoiseTerms(curve));
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(n));
}
BENCHMARK(BM_Allan24h100Hz)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
