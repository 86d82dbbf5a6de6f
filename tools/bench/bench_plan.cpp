// The calibration-protocol planner (validation/plan.h) in physical units: gyro-protocols per
// CPU-second, one gyro calibrated on one candidate's chamber runs, fitted and compensated on the
// plan's service runs (its runs simulated once per gyro and shared by the candidates using them).
//   build/bin/rlg_bench_plan
// BM_PlanGyro:          every candidate of scenarios/plan-default.toml for one gyro, one thread
// BM_PlanDefault/n/t:   the whole plan (screen, Monte Carlo, summaries) with n gyros on t threads,
//                       real time; n = 200, t = 2 is the target: 20 candidates x 200 gyros in
//                       under 60 s on 2 cores
// BM_PlanServiceGyro, BM_PlanService/n/t: the same for scenarios/plan-service.toml, whose model
//                       is selected per gyro on its own calibration runs (auto); target >= 50
//                       gyro-protocols per CPU-second

#include <benchmark/benchmark.h>

#include <ctime>
#include <numeric>

#include "io/process_memory.h"
#include "tools/source_dir.h"
#include "validation/plan.h"

namespace {

using namespace rlg;

const std::string kPlan = rlg::tools::SourcePath("scenarios/plan-default.toml");
const std::string kServicePlan = rlg::tools::SourcePath("scenarios/plan-service.toml");

// Process CPU time (every thread), s.
double ProcessCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// The candidates the Monte Carlo runs: those the model can be fitted on.
std::vector<size_t> Fittable(const validation::Planner& planner) {
  std::vector<size_t> out;
  for (size_t c = 0; c < planner.spec().candidates.size(); ++c)
    if (planner.Screen(c).failure.empty()) out.push_back(c);
  return out;
}

void PlanGyro(benchmark::State& state, const std::string& plan) {
  io::KeepFreedMemory();  // as the CLI does (io/process_memory.h)
  const validation::Planner planner(validation::LoadPlan(plan));
  const std::vector<size_t> which = Fittable(planner);
  uint64_t i = 0;
  double sink = 0.0;
  for (auto _ : state) {
    for (const auto& o : planner.RunGyro(planner.spec().seed, i++ % planner.spec().gyros, which)) sink += o.score;
  }
  benchmark::DoNotOptimize(sink);
  state.counters["gyro_protocols_per_cpu_s"] =
      benchmark::Counter(static_cast<double>(which.size()), benchmark::Counter::kIsIterationInvariantRate);
  state.counters["candidates"] = static_cast<double>(which.size());
}
void BM_PlanGyro(benchmark::State& state) { PlanGyro(state, kPlan); }
void BM_PlanServiceGyro(benchmark::State& state) { PlanGyro(state, kServicePlan); }
BENCHMARK(BM_PlanGyro)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlanServiceGyro)->Unit(benchmark::kMillisecond);

void Plan(benchmark::State& state, const std::string& plan) {
  io::KeepFreedMemory();
  validation::PlanSpec spec = validation::LoadPlan(plan);
  spec.gyros = static_cast<uint64_t>(state.range(0));
  spec.population->count = spec.gyros;
  const validation::Planner planner(spec);
  const size_t simulated = Fittable(planner).size();
  double cpu = 0.0;
  for (auto _ : state) {
    const double c0 = ProcessCpuSeconds();
    const auto r = planner.Run(static_cast<int>(state.range(1)));
    cpu += ProcessCpuSeconds() - c0;
    benchmark::DoNotOptimize(r.candidates.size());
  }
  const double protocols = static_cast<double>(simulated * spec.gyros) * static_cast<double>(state.iterations());
  state.counters["candidates"] = static_cast<double>(spec.candidates.size());
  state.counters["simulated"] = static_cast<double>(simulated);
  state.counters["gyro_protocols_per_cpu_s"] = protocols / cpu;
  state.counters["process_cpu_s"] = cpu / static_cast<double>(state.iterations());
}
void BM_PlanDefault(benchmark::State& state) { Plan(state, kPlan); }
void BM_PlanService(benchmark::State& state) { Plan(state, kServicePlan); }
BENCHMARK(BM_PlanDefault)->Args({8, 1})->Args({200, 2})->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();
BENCHMARK(BM_PlanService)->Args({8, 1})->Args({200, 2})->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
