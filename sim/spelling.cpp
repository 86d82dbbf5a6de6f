#include "sim/spelling.h"

#include <algorithm>
#include <cctype>

namespace rlg::sim {

size_t EditDistance(std::string_view a, std::string_view b) {
  auto lower = [](char c) { return static_cast<char>(std::tolower(static_cast<unsigned char>(c))); };
  // d[i][j]: edits between the first i characters of a and the first j of b, three rows kept.
  std::vector<size_t> before(b.size() + 1), previous(b.size() + 1), row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) previous[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const bool same = lower(a[i - 1]) == lower(b[j - 1]);
      row[j] = std::min({previous[j] + 1, row[j - 1] + 1, previous[j - 1] + (same ? 0 : 1)});
      if (i > 1 && j > 1 && lower(a[i - 1]) == lower(b[j - 2]) && lower(a[i - 2]) == lower(b[j - 1])) {
        row[j] = std::min(row[j], before[j - 2] + 1);  // two neighbours swapped
      }
    }
    std::swap(before, previous);
    std::swap(previous, row);
  }
  return previous[b.size()];
}

std::string NearestName(std::string_view typed, const std::vector<std::string>& names) {
  if (std::find(names.begin(), names.end(), typed) != names.end()) return "";
  std::string best;
  size_t best_distance = 0;
  for (const auto& name : names) {
    const size_t d = EditDistance(typed, name);
    const size_t shorter = std::min(typed.size(), name.size());
    const bool close = d <= std::max<size_t>(1, shorter / 3);
    // The name with its unit left out: "duration" for "duration_s" (three characters at least,
    // so that "b" is no spelling of "b0_dph").
    const bool unit_left_out = typed.size() >= 3 && name.size() > typed.size() && name[typed.size()] == '_' &&
                               EditDistance(typed, std::string_view(name).substr(0, typed.size())) == 0;
    // The stem typed in full is the stronger sign: "b1_dph" means "b1_dph_per_C", not "b0_dph".
    const size_t rank = unit_left_out ? 0 : d;
    if ((close || unit_left_out) && (best.empty() || rank < best_distance)) {
      best = name;
      best_distance = rank;
    }
  }
  return best;
}

}  // namespace rlg::sim
