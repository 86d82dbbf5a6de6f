#include "diagnosis/statistics/multistart.h"

#include <cmath>
#include <limits>

namespace rlg::diagnosis {

std::vector<double> LogGrid(double lo, double hi, double per_decade) {
  const double decades = std::log10(hi / lo);
  const int steps = std::max(1, static_cast<int>(std::ceil(per_decade * decades - 1e-9)));
  std::vector<double> out;
  for (int k = 0; k <= steps; ++k) out.push_back(lo * std::pow(10.0, decades * k / steps));
  out.back() = hi;  // exact, not lo 10^decades
  return out;
}

SearchResult CoordinateSearch(const std::function<double(const std::vector<double>&)>& objective,
                              const std::vector<double>& x0, const std::vector<std::vector<double>>& grids, int passes,
                              const std::vector<double>& diagonal) {
  SearchResult best{x0, objective(x0), 1};
  if (!std::isfinite(best.value)) best.value = std::numeric_limits<double>::infinity();
  auto try_point = [&](const std::vector<double>& x) {
    const double f = objective(x);
    ++best.evaluations;
    if (std::isfinite(f) && f < best.value) {
      best.x = x;
      best.value = f;
    }
  };
  size_t gridded = 0;
  for (const auto& g : grids) gridded += g.empty() ? 0 : 1;
  for (int pass = 0; pass < passes; ++pass) {
    for (size_t i = 0; i < grids.size(); ++i) {
      const std::vector<double> from = best.x;
      for (double v : grids[i]) {
        std::vector<double> x = from;
        x[i] = v;
        try_point(x);
      }
    }
    if (gridded < 2) continue;
    const std::vector<double> from = best.x;
    for (double factor : diagonal) {
      std::vector<double> x = from;
      bool inside = true;
      for (size_t i = 0; i < grids.size(); ++i) {
        if (grids[i].empty()) continue;
        x[i] *= factor;
        inside = inside && x[i] >= grids[i].front() && x[i] <= grids[i].back();
      }
      if (inside) try_point(x);
    }
  }
  return best;
}

}  // namespace rlg::diagnosis
