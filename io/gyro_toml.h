#pragma once
/// Writes a gyro in memory as a gyro file (scenarios/README.md, "Gyro file") that LoadGyro reads
/// back to the same gyro: load(save(g)) equals g field by field, doubles bit for bit
/// (GyroDifference, gyro_compare.h), so both simulate the same trace for a seed.
///
/// The file starts with a comment saying rlgtherm wrote it and what it is, then holds every key
/// the loader reads, defaults included, in the README's order. A number is written as the
/// shortest decimal that reads back to the same double (fmt's "{}", with ".0" added to whole
/// numbers so that each reads as a TOML float): 1e-09, 0.6, 6.328e-07.
///
/// Catalog effects. GyroConfig::effects lists effects already applied to its fields. The file
/// keeps them as what they are: the plain keys hold the gyro *without* its effects, and each
/// effect follows as an [[effects]] entry with its name, target and parameters, which LoadGyro
/// applies again, in the same order, with the same ApplyEffect. So the file reads like a
/// hand-written one (the nominal gyro, then what was added to it, by name), the provenance
/// stays, and nothing needs a plain key that the format lacks: a sensor's lag and offset, power
/// drift, and the bias terms of bias.temperature_rate, bias.gradient, bias.hysteresis, bias.play and
/// bias.mode_hop exist only as effects. The gyro without its effects is made by dropping what
/// the effects appended (the last nodes, links and radiation entries they add) and resetting the
/// fields only an effect sets to their defaults; the writer then applies the effects to it and
/// requires the result to equal the gyro, so a file is never written for a gyro it would not
/// read back as.
///
/// What the format cannot say, refused with std::invalid_argument naming the field (nothing
/// is written):
///  - a field that only an effect sets (sensor lag or offset, power drift, the effect bias
///    terms, mode hops) with a value its listed effects do not explain, or any other field
///    changed after an effect was applied;
///  - sensor-lag followers in the network (the simulator builds them from the sensors' lags);
///  - sensors, or a source's shares, out of the loader's order: it reads the tables
///    [sensors] and `shares` in the order of their keys (byte order of the names), not the
///    file's, so sensors must be sorted by channel and shares by node name;
///  - a link or radiation entry whose first end is ambient (the loader turns it around);
///  - a node index that names no node; a number that is not finite.
/// Values are not range-checked: a gyro outside the loader's physical ranges or rules (shares
/// adding up to 1, a T1 sensor, ...) is written as it is, and LoadGyro refuses the file naming
/// its line.

#include <iosfwd>
#include <string>

#include "sim/gyro.h"

namespace rlg::io {

/// Writes `gyro` as a gyro file to `out`. The text is built first and written at once, so a
/// refusal (std::invalid_argument) writes nothing; the caller checks `out`.
void WriteGyroToml(const sim::GyroConfig& gyro, std::ostream& out);

/// WriteGyroToml into `path`, whole or not at all (WriteFileAtomically, output_file.h):
/// InputError for a path the system refuses, OutputError when writing fails.
void SaveGyro(const sim::GyroConfig& gyro, const std::string& path);

}  // namespace rlg::io
