#pragma once
/// Scenario files (TOML, scenarios/README.md): runs, their ambient and power profiles, the gyro
/// file they name and an optional [population], read into the simulator's Scenario.

#include <string>

#include "sim/ambient.h"
#include "sim/population.h"
#include "sim/scenario.h"

namespace rlg::io {

class TomlReader;

/// Loads a scenario file and the gyro file it names (path relative to the scenario file). A
/// validate suite given instead is refused, naming `rlgtherm validate`.
sim::Scenario LoadScenario(const std::string& path);

/// Reads an inline profile table, e.g. { profile = "ramp", start_C = 20, rate_C_per_min = 1,
/// end_C = 60 }; `unit` is "C" (ambient) or "W" (power).
/// A ramp whose start_s lies at or after `duration_s` (the run's end) is refused at start_s.
sim::Profile ReadProfile(const TomlReader& table, const std::string& unit, double duration_s);

/// Reads a [population] table (the reader of that table); InputError naming file and line.
sim::PopulationSpec ReadPopulation(const TomlReader& table);

}  // namespace rlg::io
