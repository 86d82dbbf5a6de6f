#pragma once
// PNG figures of `diagnose --report` (PLplot, cairo PNG device): what a person looks at to
// judge a calibration and the extension it accepted.

#include "diagnosis/report.h"
#include "io/atomic_output.h"

namespace rlg::cli {

/// One figure per channel of `figures` (every temperature channel, and bias_dph when present),
/// `fit_<channel>.png` staged in `report`, with four panels over all runs laid end to end:
///   measured vs simulated (baseline and, if a step was accepted, extended) over time;
///   residual (measured - simulated) over time, on score-block means like diagnose's scores;
///   residual against temperature (ChannelFigure::temperature: the channel's own, for the bias
///   the sensor on the bias node);
///   residual against dT/dt of that temperature (°C/min).
/// The data are diagnosis::MakeDiagnosisFigures'; this file only lays them out and draws.
/// InputError if PLplot has no pngcairo device (package plplot-driver-cairo); OutputError naming
/// the figure if a PNG is incomplete after drawing (PLplot does not report write errors).
void WriteDiagnosisFigures(io::OutputDirectory& report, const diagnosis::DiagnosisFigures& figures);

}  // namespace rlg::cli
