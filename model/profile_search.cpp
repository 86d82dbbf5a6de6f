#include "model/profile_search.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>

#include "sim/errors.h"

namespace rlg::model {

bool ProfileOptions::IsValid(std::string* error) const {
  std::string why;
  if (grid_points < 3) why = fmt::format("grid_points must be at least 3 (got {})", grid_points);
  else if (!(tolerance > 0.0 && tolerance < 1.0)) why = fmt::format("tolerance must lie in (0, 1) (got {:g})", tolerance);
  if (error) *error = why;
  return why.empty();
}

std::vector<double> LogGrid(double lo, double hi, int points) {
  std::vector<double> x;
  for (int i = 0; i < points; ++i) x.push_back(std::exp(std::log(lo) + (std::log(hi) - std::log(lo)) * i / (points - 1)));
  return x;
}

ProfileResult GoldenOnLogScale(const std::function<double(double)>& f, double lo, double hi, double start,
                               double f_start, double tolerance) {
  auto value = [&](double u) {
    const double v = f(std::exp(u));
    return std::isfinite(v) ? v : std::numeric_limits<double>::infinity();
  };
  ProfileResult r;
  r.x = start;
  r.f = f_start;
  double a = std::log(lo), b = std::log(hi);
  const double ratio = 0.5 * (std::sqrt(5.0) - 1.0);
  double c = b - ratio * (b - a), d = a + ratio * (b - a);
  double fc = value(c), fd = value(d);
  while (b - a > tolerance) {
    if (fc <= fd) {
      b = d;
      d = c;
      fd = fc;
      c = b - ratio * (b - a);
      fc = value(c);
    } else {
      a = c;
      c = d;
      fc = fd;
      d = a + ratio * (b - a);
      fd = value(d);
    }
  }
  if (fc < r.f) {
    r.x = std::exp(c);
    r.f = fc;
  }
  if (fd < r.f) {
    r.x = std::exp(d);
    r.f = fd;
  }
  return r;
}

ProfileResult MinimizeOnLogScale(const std::function<double(double)>& f, double lo, double hi,
                                 const ProfileOptions& o) {
  std::string invalid;
  if (!o.IsValid(&invalid)) throw InputError("profile search: " + invalid);
  if (!(lo > 0.0 && hi > lo && std::isfinite(hi))) throw InputError(fmt::format("profile search: bounds {:g} ... {:g}: expected 0 < lo < hi", lo, hi));
  ProfileResult grid;
  grid.grid_x = LogGrid(lo, hi, o.grid_points);
  size_t best = 0;
  for (size_t i = 0; i < grid.grid_x.size(); ++i) {
    const double v = f(grid.grid_x[i]);
    grid.grid_f.push_back(std::isfinite(v) ? v : std::numeric_limits<double>::infinity());
    if (grid.grid_f[i] < grid.grid_f[best]) best = i;
  }
  const size_t m = grid.grid_x.size();
  ProfileResult r = GoldenOnLogScale(f, grid.grid_x[best > 0 ? best - 1 : 0], grid.grid_x[std::min(best + 1, m - 1)],
                                     grid.grid_x[best], grid.grid_f[best], o.tolerance);
  r.grid_x = std::move(grid.grid_x);
  r.grid_f = std::move(grid.grid_f);
  r.at_bound = best == 0 || best + 1 == m;
  return r;
}

}  // namespace rlg::model
