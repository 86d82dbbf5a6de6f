#pragma once
// Helpers shared by the CLI verbs: loading data, selecting runs, printing warnings.

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "io/csv.h"
#include "io/error_context.h"
#include "sim/errors.h"
#include "sim/trace.h"

namespace rlg::cli {

using io::AtRun;
using io::NamingFile;
using io::WithContext;
using sim::Pointers;

/// Reads a tidy CSV ("-" = stdin), printing its warnings on stderr; `keep` names extra columns
/// to keep (they must exist).
sim::Trace LoadData(const std::string& path, bool require_bias = true, const std::vector<std::string>& keep = {});
/// Writes text to a file atomically ("-" = stdout).
void WriteText(const std::string& path, const std::string& text);
/// "T1,T2" -> {"T1", "T2"}; InputError unless exactly two names.
std::array<std::string, 2> ParsePair(const std::string& text);

}  // namespace rlg::cli
