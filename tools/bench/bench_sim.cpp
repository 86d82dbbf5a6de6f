// Simulator throughput in physical units: simulated gyro-hours per CPU-second.
//   build/bin/rlg_bench --benchmark_filter=Simulate
// Each iteration simulates one run of `hours` at 1 s output (3600 samples per hour) with all
// physics and noise on; items/s = samples/s, and the "gyro_h_per_cpu_s" counter is the unit docs/performance.md reports.

#include <benchmark/benchmark.h>

#include <array>
#include <cstdlib>  // defines __GLIBC__ on glibc (through <features.h>)
#include <fmt/format.h>
#include <ostream>
#include <streambuf>
#ifdef __GLIBC__
#include <malloc.h>
#endif

#include "io/csv.h"
#include "io/gyro_file.h"
#include "io/npz.h"
#include "io/process_memory.h"
#include "sim/ambient.h"
#include "sim/gyro.h"
#include "sim/noise.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "tools/source_dir.h"

namespace {

using namespace rlg::sim;
namespace io = rlg::io;

GyroConfig DefaultGyro() { return io::LoadGyro(rlg::tools::SourcePath("scenarios/gyros/default.toml")); }

/// A chain of n nodes (block-like capacities), heated at one end, each losing heat to ambient.
GyroConfig Chain(int n) {
  GyroConfig g = DefaultGyro();
  NetworkSpec net;
  for (int i = 0; i < n; ++i) net.nodes.push_back({fmt::format("n{}", i), 50.0 + 20.0 * i});
  for (int i = 0; i + 1 < n; ++i) net.links.push_back({i, i + 1, 0.3});
  for (int i = 0; i < n; ++i) net.links.push_back({i, kAmbient, 0.02});
  net.sources.push_back({"discharge", {{0, 0.5}, {n / 2, 0.5}}, 0.7});
  g.network = net;
  g.sensors.resize(4);
  for (int s = 0; s < 4; ++s) g.sensors[s].node = s * (n - 1) / 3;
  g.bias.node = n / 2;
  g.bias.langmuir_gradients = {{0, n / 2, 0.1}};
  return g;
}

RunSpec RampRun(double hours) {
  RunSpec r;
  r.id = "bench";
  r.duration_s = hours * 3600.0;
  r.sample_period_s = 1.0;
  // Ramps up and down so breakpoints and restarts are part of the cost.
  std::vector<std::pair<double, double>> pts;
  for (double t = 0.0; t <= r.duration_s; t += 7200.0) pts.emplace_back(t, (static_cast<int>(t / 7200.0) % 2) ? 60.0 : 0.0);
  r.ambient = Profile::Table(pts);
  return r;
}

void Report(benchmark::State& state, double hours) {
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(hours * 3600.0));
  state.counters["gyro_h_per_cpu_s"] =
      benchmark::Counter(hours * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

/// A fresh Run per run, from a heap that keeps freed memory, as the CLI's and the Dask shards'
/// (main below; io/process_memory.h): the columns of the run before are reused without page faults.
void BM_SimulateDefaultGyro(benchmark::State& state) {
  const GyroConfig gyro = DefaultGyro();
  const double hours = static_cast<double>(state.range(0));
  const RunSpec run = RampRun(hours);
  uint64_t seed = 1;
  for (auto _ : state) benchmark::DoNotOptimize(SimulateRun(gyro, run, seed++, 0));
  Report(state, hours);
}
BENCHMARK(BM_SimulateDefaultGyro)->Arg(24)->Arg(240)->Unit(benchmark::kMillisecond);

/// The same from a heap that hands every column back to the kernel when freed (each one mapped
/// on its own, glibc's mmap threshold at 64 kB): every run first-touches 4.8 MB of fresh pages,
/// as the first run of a process does. What that costs is the kernel's and the hypervisor's
/// (docs/performance.md, "Simulation").
void BM_SimulateDefaultGyroFreshPages(benchmark::State& state) {
#ifdef __GLIBC__
  mallopt(M_MMAP_THRESHOLD, 64 << 10);
#endif
  BM_SimulateDefaultGyro(state);
  rlg::io::KeepFreedMemory();  // back to the other benchmarks' heap
}
BENCHMARK(BM_SimulateDefaultGyroFreshPages)->Arg(24)->Unit(benchmark::kMillisecond);

/// The same runs written into one reused Run (SimulateRun's out-parameter overload), as a
/// population on a thread pool would: no allocation or first touch of fresh pages per run.
void BM_SimulateDefaultGyroReuse(benchmark::State& state) {
  const GyroConfig gyro = DefaultGyro();
  const double hours = static_cast<double>(state.range(0));
  const RunSpec run = RampRun(hours);
  uint64_t seed = 1;
  Run out;
  for (auto _ : state) {
    SimulateRun(gyro, run, seed++, 0, &out);
    benchmark::DoNotOptimize(out.columns.back().data());
    benchmark::ClobberMemory();
  }
  Report(state, hours);
}
BENCHMARK(BM_SimulateDefaultGyroReuse)->Arg(24)->Arg(240)->Unit(benchmark::kMillisecond);

void BM_SimulateDefaultGyroCvode(benchmark::State& state) {
  const GyroConfig gyro = DefaultGyro();
  const RunSpec run = RampRun(24.0);
  SolverOptions cvode;
  cvode.method = ThermalMethod::kCvode;
  uint64_t seed = 1;
  for (auto _ : state) benchmark::DoNotOptimize(SimulateRun(gyro, run, seed++, 0, cvode));
  Report(state, 24.0);
}
BENCHMARK(BM_SimulateDefaultGyroCvode)->Unit(benchmark::kMillisecond);

void BM_SimulateDefaultGyroNoNoise(benchmark::State& state) {
  GyroConfig gyro = DefaultGyro();
  gyro.noise = GyroNoiseParams{};
  for (auto& s : gyro.sensors) s.noise = SensorNoiseParams{};
  const RunSpec run = RampRun(24.0);
  uint64_t seed = 1;
  for (auto _ : state) benchmark::DoNotOptimize(SimulateRun(gyro, run, seed++, 0));
  Report(state, 24.0);
}
BENCHMARK(BM_SimulateDefaultGyroNoNoise)->Unit(benchmark::kMillisecond);

/// Thermal network only (no sensors, bias or noise): the like-for-like figure for
/// tools/bench/scipy_reference.py. Arg 0 = exact propagator, 1 = CVODE.
void BM_ThermalOnlyDefaultNetwork(benchmark::State& state) {
  const GyroConfig gyro = DefaultGyro();
  std::vector<int> sensor_state;
  const ThermalNetwork net = BuildNetwork(gyro, &sensor_state);
  std::vector<Profile> power;
  for (const auto& s : gyro.network.sources) power.push_back(Profile::Constant(s.power_W));
  const RunSpec run = RampRun(24.0);
  const ThermalSystem system(net, run.ambient, power);
  std::vector<double> times(86401);
  for (size_t k = 0; k < times.size(); ++k) times[k] = static_cast<double>(k);
  SolverOptions options;
  options.method = state.range(0) == 0 ? ThermalMethod::kExactLinear : ThermalMethod::kCvode;
  double sink = 0.0;
  for (auto _ : state) {
    IntegrateThermal(system, times, Eigen::VectorXd::Zero(net.num_states()), options,
                     [&](size_t, double, const Eigen::VectorXd& x, const Eigen::VectorXd&) { sink += x[0]; });
  }
  benchmark::DoNotOptimize(sink);
  state.SetLabel(state.range(0) == 0 ? "exact" : "cvode");
  Report(state, 24.0);
}
BENCHMARK(BM_ThermalOnlyDefaultNetwork)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

using Writer = void (*)(const Trace&, std::ostream&);

/// A stream that only counts its bytes: the writers' own cost, without a growing string's copies
/// and fresh pages (which on this machine cost more than the formatting) or a disk.
class CountingBuf : public std::streambuf {
 public:
  int64_t count = 0;

 protected:
  int_type overflow(int_type c) override {
    ++count;
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char*, std::streamsize n) override {
    count += n;
    return n;
  }
};

/// Simulation and writing the run, as `simulate -o` does (minus the disk).
void SimulateAndWrite(benchmark::State& state, Writer write) {
  const GyroConfig gyro = DefaultGyro();
  const double hours = static_cast<double>(state.range(0));
  const RunSpec run = RampRun(hours);
  uint64_t seed = 1;
  for (auto _ : state) {
    Trace t;
    t.runs.push_back(SimulateRun(gyro, run, seed++, 0));
    CountingBuf buf;
    std::ostream out(&buf);
    write(t, out);
    benchmark::DoNotOptimize(buf.count);
  }
  Report(state, hours);
}
void BM_SimulateDefaultGyroWithCsv(benchmark::State& state) { SimulateAndWrite(state, io::WriteTraceCsv); }
BENCHMARK(BM_SimulateDefaultGyroWithCsv)->Arg(24)->Unit(benchmark::kMillisecond);
void BM_SimulateDefaultGyroWithNpz(benchmark::State& state) { SimulateAndWrite(state, io::WriteTraceNpz); }
BENCHMARK(BM_SimulateDefaultGyroWithNpz)->Arg(24)->Unit(benchmark::kMillisecond);

/// Writing alone, one simulated 24 h run (86,401 samples of t_s and 6 columns): samples/s and
/// bytes/s of the output. Arg 0 = tidy CSV, 1 = .npz.
void BM_WriteTrace(benchmark::State& state) {
  Trace t;
  t.runs.push_back(SimulateRun(DefaultGyro(), RampRun(24.0), 1, 0));
  const Writer write = state.range(0) == 0 ? io::WriteTraceCsv : io::WriteTraceNpz;
  int64_t bytes = 0;
  for (auto _ : state) {
    CountingBuf buf;
    std::ostream out(&buf);
    write(t, out);
    bytes = buf.count;
    benchmark::DoNotOptimize(bytes);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(t.runs[0].size()));
  state.SetBytesProcessed(state.iterations() * bytes);
  state.SetLabel(state.range(0) == 0 ? "csv" : "npz");
}
BENCHMARK(BM_WriteTrace)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_Simulate16NodeNetwork(benchmark::State& state) {
  const GyroConfig gyro = Chain(16);
  const RunSpec run = RampRun(24.0);
  uint64_t seed = 1;
  for (auto _ : state) benchmark::DoNotOptimize(SimulateRun(gyro, run, seed++, 0));
  Report(state, 24.0);
}
BENCHMARK(BM_Simulate16NodeNetwork)->Unit(benchmark::kMillisecond);

/// Simplifying a logged input as `diagnose` does for every run's ambient and powers (one point
/// per second): a constant (a simulated ambient, a logged power) and a noisy one, 24 h at 1 s.
/// Arg 0 = constant, 1 = a uniform wobble of +-0.06 °C at a tolerance of 0.05 °C. Linear in the points.
void BM_SimplifyPolyline(benchmark::State& state) {
  std::vector<std::pair<double, double>> pts;
  uint64_t x = 1;
  for (int k = 0; k < 86400; ++k) {
    x = x * 6364136223846793005ULL + 1442695040888963407ULL;  // a fixed wobble, no library draw
    const double u = static_cast<double>(x >> 11) * 0x1p-53 - 0.5;
    pts.emplace_back(static_cast<double>(k), 20.0 + (state.range(0) == 1 ? 0.12 * u : 0.0));
  }
  size_t kept = 0;
  for (auto _ : state) kept = SimplifyPolyline(pts, 0.05).size();
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(pts.size()));
  state.SetLabel(fmt::format("{} kept", kept));
}
BENCHMARK(BM_SimplifyPolyline)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// The floor under the noise: one standard normal draw (Boost ziggurat on PCG64, as the
/// simulator's Rng makes them), one at a time. The default gyro draws ~6.5 per 1 s sample
/// (ARW, four temperature sensors, ~1.5 flicker updates).
void BM_NormalDraw(benchmark::State& state) {
  Rng rng(1, 0);
  double sink = 0.0;
  for (auto _ : state) sink += rng.Normal();
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_NormalDraw);

/// The same draws 256 at a time into a buffer (Rng::Fill), as the simulator's noise takes them.
void BM_NormalFill(benchmark::State& state) {
  Rng rng(1, 0);
  std::array<double, 256> block;
  for (auto _ : state) {
    rng.Fill(block.data(), block.size());
    benchmark::DoNotOptimize(block.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(block.size()));
}
BENCHMARK(BM_NormalFill);

}  // namespace

int main(int argc, char** argv) {
  rlg::io::KeepFreedMemory();  // the CLI's heap (io/process_memory.h); FreshPages changes it for its own runs
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
