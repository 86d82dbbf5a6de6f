#pragma once
/// A plug-in compensator: an external command that compensates a run the way the user's own
/// algorithm does, so that `rlgtherm validate` scores it beside Eq. (2) with the same metrics
/// (compensation/evaluation.h) and the same checks (validation/suite.h). The protocol
/// (docs/data-format.md, "Plug-in compensators"):
///
///   run      `/bin/sh -c COMMAND` in the suite file's directory, once per compensated run
///   stdin    that run as tidy CSV: header run,t_s,T_amb,T1..,bias_dph, one row per sample
///   stdout   the compensated bias (°/h), one value per input row, in row order, either
///            - one number per line, or
///            - a CSV whose header names the column (default `compensated_dph`), one row per
///              input row (other columns are ignored);
///            empty lines and lines starting with '#' are skipped
///   status   0; anything else (or a signal) is an error, reported with the end of its stderr
///   fds      0, 1 and 2 only: no other descriptor of rlgtherm's, nor another plug-in's pipes
///            (plug-ins run side by side on a population's threads)
///
/// Every value must be a finite number and there must be exactly as many as rows: anything else
/// is an InputError naming the compensator, the run and the output line (exit status 2).

#include <string>
#include <vector>

#include "sim/trace.h"

namespace rlg::validation {

struct PluginCompensator {
  std::string name;                       ///< how the reports name it (not "eq2")
  std::string command;                    ///< a shell command line
  std::string directory = ".";            ///< its working directory (the suite file's)
  std::string column = "compensated_dph";  ///< the column read when the output is a CSV
};

/// Runs the plug-in on `run` and returns its compensated bias, one value per sample.
std::vector<double> RunPlugin(const PluginCompensator& plugin, const sim::Run& run);

/// Reads a plug-in's standard output (the format above); `rows` values expected. `who` begins
/// every message ("compensator 'x' on run 'r'").
std::vector<double> ParsePluginOutput(const std::string& text, size_t rows, const std::string& column,
                                      const std::string& who);

}  // namespace rlg::validation
