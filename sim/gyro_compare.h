#pragma once
/// Field-by-field comparison of two gyros: every field of GyroConfig (network, sensors, bias,
/// noise, effects, calibration, name), numbers bit for bit (0.0 and -0.0 differ, as two
/// different doubles do however close). The gyro writer uses it to check that what it writes
/// means the gyro it was given (gyro_toml.h); tests use it for round trips.
///
/// When a field is added to one of the structs a gyro is made of, this comparison, the writer
/// and the loader must learn it: a size check in gyro_compare.cpp fails to compile until the
/// comparison is updated.

#include <string>

#include "sim/gyro.h"

namespace rlg::sim {

/// The first field in which `a` and `b` differ, e.g. "sensors[1] (T2).offset_C: 0.1 != 0.2"
/// (a's value first), or "" when every field is identical.
std::string GyroDifference(const GyroConfig& a, const GyroConfig& b);

}  // namespace rlg::sim
