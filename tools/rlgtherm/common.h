#pragma once
// Helpers shared by the CLI verbs: loading data, selecting runs, printing warnings.

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "sim/csv.h"
#include "sim/trace.h"

namespace rlg::cli {

/// Reads a tidy CSV ("-" = stdin), printing its warnings on stderr; `keep` names extra columns
/// to keep (they must exist).
sim::Trace LoadData(const std::string& path, bool require_bias = true, const std::vector<std::string>& keep = {});
/// Copies of `runs`, each replaced by its block means over `average_s` (no averaging when 0).
std::vector<sim::Run> Averaged(const std::vector<const sim::Run*>& runs, double average_s);
std::vector<const sim::Run*> Pointers(const std::vector<sim::Run>& runs);
/// Writes text to a file atomically ("-" = stdout).
void WriteText(const std::string& path, const std::string& text);
/// "T1,T2" -> {"T1", "T2"}; InputError unless exactly two names.
std::array<std::string, 2> ParsePair(const std::string& text);

}  // namespace rlg::cli
