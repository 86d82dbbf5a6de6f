// libFuzzer harness: the scenario loader (io::LoadScenario) with the gyro file it names, then
// `simulate` on a shortened copy. An input is a scenario file, optionally followed by a line
// "#@gyro" and a gyro file written beside it as gyro.toml (else gyro.toml is the default gyro).
// Properties, on every input:
//  - only InputError escapes the loaders (anything else is `rlgtherm: internal error`, exit 1);
//  - an accepted scenario (runs cut to at most 16 samples, CVODE to 2000 steps an output) simulates
//    without undefined behaviour, or fails with NumericalError (exit 3); what CheckReadable
//    passes, the tidy CSV reader reads back: `simulate` never writes a file it refuses.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#include "io/csv.h"
#include "io/scenario_file.h"
#include "sim/errors.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "tests/fuzz/fuzz_util.h"
#include "tools/source_dir.h"

namespace {

std::string DefaultGyro() {
  std::ifstream in(rlg::tools::SourcePath("scenarios/gyros/default.toml"));
  std::stringstream s;
  s << in.rdbuf();
  rlg::fuzz::Check(!s.str().empty(), "reading scenarios/gyros/default.toml");
  return s.str();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace rlg;
  static const fuzz::ScratchDir dir;
  static const std::string default_gyro = DefaultGyro();
  const std::string input(reinterpret_cast<const char*>(data), size);
  const size_t marker = input.find("#@gyro\n");
  // Most inputs name the default gyro: its file is rewritten only when an input's gyro differs.
  static std::string written_gyro;
  const std::string gyro = marker == std::string::npos ? default_gyro : input.substr(marker + 7);
  if (gyro != written_gyro || written_gyro.empty()) {
    dir.Write("gyro.toml", gyro);
    written_gyro = gyro;
  }
  const std::string path = dir.Write("scenario.toml", input.substr(0, marker));
  sim::Scenario sc;
  try {
    sc = io::LoadScenario(path);
  } catch (const InputError&) {
    return 0;
  }
  // The cuts bound an input's cost: a 1 ms sine under 1 s samples took CVODE 20000 steps a
  // sample, 6.6 s an input at 64 samples (docs/testing.md, "Fuzzing"); a run this short still
  // crosses every breakpoint kind, and giving up is NumericalError, a documented exit.
  for (auto& run : sc.runs) run.duration_s = std::min(run.duration_s, 16.0 * run.sample_period_s);
  sc.solver.cvode.max_steps = std::min(sc.solver.cvode.max_steps, 2000L);
  sim::Trace trace;
  try {
    trace = sim::SimulateScenario(sc, sc.seed);
    sim::CheckReadable(sc, trace);
  } catch (const NumericalError&) {
    return 0;
  } catch (const InputError&) {
    return 0;  // refused, with the run, time and value: nothing would be written
  }
  std::istringstream written(io::FormatTraceCsv(trace));
  try {
    io::ReadTraceCsv(written, "simulated.csv");
  } catch (const InputError& e) {
    fuzz::Check(false, std::string("simulate would write a file its reader refuses: ") + e.what());
  }
  return 0;
}
