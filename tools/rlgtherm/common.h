#pragma once
// Helpers shared by the CLI verbs: loading data, selecting runs, printing warnings.

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/csv.h"
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
/// Calls f(); an InputError or NumericalError whose message does not begin with `source` yet
/// gets `where` in front, so that every refusal about data names the file (and, for a run, the
/// line of its first row and the run).
template <typename F>
auto WithContext(const std::string& source, const std::string& where, F&& f) -> decltype(f()) {
  auto named = [&](const char* what) {
    return !source.empty() && std::string_view(what).rfind(source, 0) == 0 ? std::string(what)
                                                                           : fmt::format("{}: {}", where, what);
  };
  try {
    return f();
  } catch (const InputError& e) {
    throw InputError(named(e.what()));
  } catch (const NumericalError& e) {
    throw NumericalError(named(e.what()));
  }
}
/// WithContext for work on one run: run.Where() ("file:line: run 'id'").
template <typename F>
auto AtRun(const sim::Run& run, F&& f) -> decltype(f()) {
  return WithContext(run.source, run.Where(), std::forward<F>(f));
}
/// WithContext for work on a whole data file: its path.
template <typename F>
auto NamingFile(const std::string& path, F&& f) -> decltype(f()) {
  return WithContext(path, path, std::forward<F>(f));
}

/// "T1,T2" -> {"T1", "T2"}; InputError unless exactly two names.
std::array<std::string, 2> ParsePair(const std::string& text);

}  // namespace rlg::cli
