#pragma once
/// Scenario / suite files: a gyro plus a list of runs, each with an ambient profile, a
/// duration and a sample period (scenarios/README.md documents every key).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sim/ambient.h"
#include "sim/cvode_integrator.h"
#include "sim/gyro.h"
#include "sim/population.h"
#include "sim/solver_options.h"

namespace rlg::sim {

struct RunSpec {
  std::string id;
  double duration_s = 7200.0;
  double sample_period_s = 1.0;
  Profile ambient = Profile::Constant(20.0);
  std::map<std::string, Profile> power;  ///< source name -> power profile (W), overriding power_W
  std::optional<double> initial_C;       ///< all nodes start here; default: soaked at ambient(0)
  int line = 0;                          ///< line of its [[runs]] table in the scenario (messages)
};

struct Scenario {
  std::string path;
  GyroConfig gyro;
  std::vector<RunSpec> runs;
  SolverOptions solver;
  uint64_t seed = 1;
  /// [population]: a part-to-part spread of the gyro (sim/population.h); `simulate --gyro I`
  /// simulates gyro I of it, with its seed.
  std::optional<PopulationSpec> population;
};

}  // namespace rlg::sim
