#pragma once
/// Converters from measured logs to the tidy CSV's Trace (docs/data-format.md).

#include <string>

#include "sim/trace.h"

namespace rlg::sim {

struct TclabOptions {
  /// Nominal heater powers per percent of drive (data/tclab/SOURCE.md); `diagnose`
  /// calibrates the gains, so these only set the starting point.
  double heater1_W_per_percent = 0.01;
  double heater2_W_per_percent = 0.0075;
};

/// One TCLab log (columns: time s, heater 1 %, heater 2 %, T1 °C, T2 °C, anything else
/// ignored; with or without a header line) as a run named after the file: columns T1, T2,
/// P_heater1_W, P_heater2_W, time from the first sample. InputError naming file and line.
Run ImportTclab(const std::string& path, const TclabOptions& options = {});

}  // namespace rlg::sim
