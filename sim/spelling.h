#pragma once
/// Misspelt names in files: which of the names a reader knows a typed one most likely meant, so
/// that a refusal can say "unknown key 'nmae'; did you mean 'name'?" (the TOML files' keys,
/// io/toml_reader.h; the coefficient file's, model/coefficients_json.h).

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace rlg::sim {

/// Edits between `a` and `b`, ignoring case: insertions, deletions, substitutions and swaps of
/// two neighbouring characters (the optimal string alignment distance).
size_t EditDistance(std::string_view a, std::string_view b);

/// The name of `names` that `typed` most likely misspells, or "" when none is close. Close: at
/// most one edit per three characters of the shorter of the two, and at least one edit allowed
/// ("nmae", "Name" and "nam" for "name"), or the name is `typed` followed by a unit suffix
/// ("duration" for "duration_s", "conductance" for "conductance_W_per_K"). A name of the second
/// kind wins ("b1_dph" means "b1_dph_per_C", not "b0_dph"), else the nearest; ties go to the
/// first in `names`. `typed` itself, if among `names`, misspells nothing.
std::string NearestName(std::string_view typed, const std::vector<std::string>& names);

}  // namespace rlg::sim
