// Fitting, compensation and Allan throughput.
//   build/bin/rlg_bench_model
// BM_JointFit:              Eq. (2) joint fit of 10 runs x 7,200 samples (target < 5 ms)
// BM_FitAuto:               auto (model/model_selection.h) on the paper's nine fixed warm-ups and
//                           varying-train.toml's five ramps, 14 runs of 2-2.5 h at 1 s (target
//                           well under 1 s)
// BM_StreamingCompensation: Compensator::Update per sample (target >= 10 M samples/s)
// BM_Allan24h100Hz:         overlapping Allan deviation + read-offs of 24 h at 100 Hz (target << 1 s)
// BM_EvaluateRun:           one compensated paper run's evaluation (compensation/evaluation.h:
//                           stabilities, peaks, trend, Allan curve and read-offs), as a population
//                           suite evaluates ten per gyro
// BM_DiagnosePaperFixed/s:  rlgtherm diagnose on paper-fixed (10 runs x 2 h at 1 s) simulated
//                           with seed s, full catalog, default gyro (target < 30 s)
// BM_DiagnoseTclab:         diagnose on the four TCLab runs, per-run heater gains (target < 5 s)
// BM_PopulationPaperProtocol/n: scenarios/paper-population.toml per gyro on n threads (gyros/s, real time)

#include <benchmark/benchmark.h>

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>

#include "compensation/compensator.h"
#include "compensation/evaluation.h"
#include "io/gyro_file.h"
#include "io/import.h"
#include "io/process_memory.h"
#include "io/scenario_file.h"
#include "model/allan.h"
#include "diagnosis/diagnose.h"
#include "model/guo2006.h"
#include "model/model_selection.h"
#include "sim/gyro.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "tools/source_dir.h"
#include "validation/population_suite.h"

namespace {

using namespace rlg;

const sim::Trace& PaperFixed() {
  static const sim::Trace trace = [] {
    const sim::Scenario sc = io::LoadScenario(rlg::tools::SourcePath("scenarios/paper-fixed.toml"));
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

void BM_FitAuto(benchmark::State& state) {
  static const sim::Trace ramps = [] {
    const sim::Scenario sc = io::LoadScenario(rlg::tools::SourcePath("scenarios/varying-train.toml"));
    return sim::SimulateScenario(sc, sc.seed);
  }();
  std::vector<const sim::Run*> runs;
  for (const auto& r : PaperFixed().runs)
    if (r.id != "fixed+60") runs.push_back(&r);
  for (const auto& r : ramps.runs) runs.push_back(&r);
  size_t samples = 0;
  for (const auto* r : runs) samples += r->size();
  model::PolyModel m;
  for (auto _ : state) benchmark::DoNotOptimize(m = model::FitAuto(runs, model::AutoOptions{}));
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * samples));
  state.counters["runs"] = static_cast<double>(runs.size());
  state.counters["models_scored"] = static_cast<double>(m.selection->visited.size());
}
BENCHMARK(BM_FitAuto)->Unit(benchmark::kMillisecond);

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

void BM_EvaluateRun(benchmark::State& state) {
  std::vector<const sim::Run*> runs;
  for (const auto& r : PaperFixed().runs) runs.push_back(&r);
  const model::Guo2006Coefficients c = model::FitGuo2006(runs, model::FitOptions{});
  const sim::Run& run = PaperFixed().runs[5];  // fixed+20: 7,201 samples at 1 s
  const std::vector<double> compensated = compensation::CompensateRun(c, run);
  for (auto _ : state) benchmark::DoNotOptimize(compensation::EvaluateRun(run, compensated, c));
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(run.size()));
}
BENCHMARK(BM_EvaluateRun)->Unit(benchmark::kMicrosecond);

}  // namespace

void BM_DiagnosePaperFixed(benchmark::State& state) {
  const sim::Scenario sc = io::LoadScenario(rlg::tools::SourcePath("scenarios/paper-fixed.toml"));
  const sim::Trace data = sim::SimulateScenario(sc, static_cast<uint64_t>(state.range(0)));
  const sim::GyroConfig gyro = io::LoadGyro(rlg::tools::SourcePath("scenarios/gyros/default.toml"));
  for (auto _ : state) benchmark::DoNotOptimize(diagnosis::Diagnose(data, gyro, diagnosis::DiagnoseOptions{}));
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(data.runs.size() * data.runs.front().size()));
}
BENCHMARK(BM_DiagnosePaperFixed)->Arg(1)->Arg(2)->Arg(3)->Unit(benchmark::kSecond)->Iterations(1);

void BM_DiagnoseTclab(benchmark::State& state) {
  const std::string dir = rlg::tools::SourcePath("data/tclab/");
  sim::Trace data;
  for (const char* f : {"mimo_2nd_order_600s.txt", "mimo_energy_balance_600s.txt", "mimo_hybrid_600s.txt",
                        "mimo_mhe_nonlinear_noheader.txt"})
    data.runs.push_back(io::ImportTclab(dir + f));
  const sim::GyroConfig gyro = io::LoadGyro(rlg::tools::SourcePath("scenarios/gyros/tclab-nominal.toml"));
  diagnosis::DiagnoseOptions o;
  o.per_run_source_gains = true;
  for (auto _ : state) benchmark::DoNotOptimize(diagnosis::Diagnose(data, gyro, o));
}
BENCHMARK(BM_DiagnoseTclab)->Unit(benchmark::kSecond)->Iterations(1);

// A population suite (validation/population_suite.h): scenarios/paper-population.toml's
// protocol (ten 2 h fixed-ambient runs simulated, Eq. (2) fitted on nine, all ten compensated,
// Table 1 and checks) per gyro. Arg = threads; real time, so the gyros/s counter at 2 threads
// over the one at 1 is the scaling on this machine. 64 gyros per iteration.
void BM_PopulationPaperProtocol(benchmark::State& state) {
  rlg::io::KeepFreedMemory();  // as the CLI and the Dask shards do (io/process_memory.h)
  const rlg::validation::PopulationSuite suite(
      rlg::validation::LoadSuite(rlg::tools::SourcePath("scenarios/paper-population.toml")));
  constexpr uint64_t kGyros = 64;
  uint64_t first = 0;
  double sink = 0.0;
  for (auto _ : state) {
    rlg::validation::RunPopulation(suite, first, kGyros, static_cast<int>(state.range(0)),
                                     [&](const rlg::validation::GyroOutcome& g) { sink += g.metrics[0]; });
    first = (first + kGyros) % (suite.population().count() - kGyros);
  }
  benchmark::DoNotOptimize(sink);
  state.counters["gyros_per_s"] = benchmark::Counter(static_cast<double>(kGyros * state.iterations()),
                                                     benchmark::Counter::kIsRate);
  // Simulated gyro-hours of the protocol: ten 2 h runs per gyro.
  state.counters["gyro_h_per_s"] = benchmark::Counter(20.0 * static_cast<double>(kGyros * state.iterations()),
                                                      benchmark::Counter::kIsRate);
}
BENCHMARK(BM_PopulationPaperProtocol)->Arg(1)->Arg(2)->Unit(benchmark::kSecond)->UseRealTime()->MinTime(5.0);

BENCHMARK_MAIN();
