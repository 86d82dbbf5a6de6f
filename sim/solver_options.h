#pragma once
/// Choice of thermal integrator for a run (scenario key [solver], scenarios/README.md).

#include "sim/cvode_integrator.h"

namespace rlg::sim {

/// How the thermal network is integrated. kAuto takes the exact matrix-exponential propagator
/// when the network is linear and every input is piecewise linear (constant, ramp, table,
/// steps), and CVODE otherwise (radiation, power drift, sine inputs).
enum class ThermalMethod { kAuto, kCvode, kExactLinear };

struct SolverOptions {
  ThermalMethod method = ThermalMethod::kAuto;
  IntegratorOptions cvode;
};

}  // namespace rlg::sim
