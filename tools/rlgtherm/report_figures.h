#pragma once
// PNG figures of `diagnose --report` (PLplot, cairo PNG device): what a person looks at to
// judge a calibration and the extension it accepted.

#include <string>
#include <vector>

#include "model/diagnose.h"

namespace rlg::cli {

/// dT/dt (°C/min) of block means T at times t (s): central differences, one-sided at the ends.
std::vector<double> RatePerMinute(const std::vector<double>& t, const std::vector<double>& T);

/// One figure per channel (every temperature channel, and bias_dph when present),
/// `<dir>/fit_<channel>.png`, with four panels over all runs laid end to end:
///   measured vs simulated (baseline and, if a step was accepted, extended) over time;
///   residual (measured - simulated) over time, on score_block_s means like diagnose's scores;
///   residual against temperature (the channel's own; for the bias, `bias_temperature`'s);
///   residual against dT/dt of that temperature (°C/min, central differences of block means).
/// Returns the file names written. InputError if PLplot has no pngcairo device
/// (package plplot-driver-cairo).
std::vector<std::string> WriteDiagnosisFigures(const std::string& dir, const model::Diagnosis& d,
                                               const std::string& bias_temperature, double score_block_s);

}  // namespace rlg::cli
