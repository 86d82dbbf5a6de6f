#pragma once
/// Gyro files (TOML, scenarios/README.md "Gyro files"): read into the simulator's GyroConfig
/// with every key checked; io/gyro_toml.h writes them back.

#include <string>

#include "sim/gyro.h"

namespace rlg::io {

class TomlReader;

/// Loads and validates a gyro file; unknown keys, bad values and unknown node names raise
/// InputError naming file and line.
sim::GyroConfig LoadGyro(const std::string& path);

/// Reads one [[effects]] table.
sim::EffectSpec ReadEffect(const TomlReader& table);
/// Reads [[effects]] of `table` and applies each (sim::ApplyEffect), rethrowing errors with file
/// and line.
void ReadAndApplyEffects(const TomlReader& table, sim::GyroConfig& gyro);

}  // namespace rlg::io
