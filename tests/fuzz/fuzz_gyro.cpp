// libFuzzer harness: the TOML gyro loader (io::LoadGyro; it takes a path, so each input is
// written to a private file first). Properties, on every input:
//  - only InputError escapes (anything else is `rlgtherm: internal error`, exit 1);
//  - an accepted gyro simulates a few samples at 20 °C without undefined behaviour (the
//    sanitizers watch) and to finite values, or fails with NumericalError (exit 3, a solver
//    giving up on a legal but extreme network).

#include <cstddef>
#include <cstdint>
#include <string>

#include "io/gyro_file.h"
#include "sim/errors.h"
#include "sim/gyro.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "tests/fuzz/fuzz_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rlg;
  static const fuzz::ScratchDir dir;
  const std::string path = dir.Write("gyro.toml", std::string(reinterpret_cast<const char*>(data), size));
  sim::GyroConfig gyro;
  try {
    gyro = io::LoadGyro(path);
  } catch (const InputError&) {
    return 0;
  }
  sim::RunSpec run;
  run.id = "fuzz";
  run.duration_s = 4.0;
  run.sample_period_s = 1.0;
  for (const auto& src : gyro.network.sources) {
    if (src.driven_by_data) run.power.emplace(src.name, sim::Profile::Constant(1.0));
  }
  sim::SolverOptions solver;
  solver.cvode.max_steps = 20000;  // a legal but stiff network may give up (NumericalError) instead of taking seconds
  try {
    const sim::Run r = sim::SimulateRun(gyro, run, 1, 0, solver);
    for (size_t c = 0; c < r.names.size(); ++c)
      for (double v : r.columns[c]) fuzz::CheckFinite(v, "simulated " + r.names[c]);
  } catch (const NumericalError&) {
  }
  return 0;
}
