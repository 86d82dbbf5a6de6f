#pragma once
// PNG figures of `diagnose --report` (PLplot, cairo PNG device): what a person looks at to
// judge a calibration and the extension it accepted.

#include <string>
#include <vector>

#include "model/diagnose.h"
#include "sim/output_file.h"

namespace rlg::cli {

/// dT/dt (°C/min) of block means T at times t (s): central differences, one-sided at the ends.
std::vector<double> RatePerMinute(const std::vector<double>& t, const std::vector<double>& T);

/// One figure per channel (every temperature channel, and bias_dph when present),
/// `fit_<channel>.png` staged in `report`, with four panels over all runs laid end to end:
///   measured vs simulated (baseline and, if a step was accepted, extended) over time;
///   residual (measured - simulated) over time, on score_block_s means like diagnose's scores;
///   residual against temperature (the channel's own; for the bias, `bias_temperature`'s);
///   residual against dT/dt of that temperature (°C/min, central differences of block means).
/// InputError if PLplot has no pngcairo device (package plplot-driver-cairo); OutputError naming
/// the figure if a PNG is incomplete after drawing (PLplot does not report write errors).
void WriteDiagnosisFigures(sim::OutputDirectory& report, const model::Diagnosis& d, const std::string& bias_temperature,
                           double score_block_s);

}  // namespace rlg::cli
