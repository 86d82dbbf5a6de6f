#pragma once
// Helpers shared by the CLI verbs: loading data, selecting runs, printing warnings.

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "sim/csv.h"
#include "sim/errors.h"
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
/// Calls f() for work on one run: an InputError that does not say where yet (its message does
/// not begin with the run's file) gets run.Where() in front, so that every refusal about data
/// names the file, the line of the run's first row and the run.
template <typename F>
auto AtRun(const sim::Run& run, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const InputError& e) {
    if (!run.source.empty() && std::string_view(e.what()).rfind(run.source, 0) == 0) throw;
    throw InputError(fmt::format("{}: {}", run.Where(), e.what()));
  }
}

/// "T1,T2" -> {"T1", "T2"}; InputError unless exactly two names.
std::array<std::string, 2> ParsePair(const std::string& text);

}  // namespace rlg::cli
