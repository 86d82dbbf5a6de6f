#pragma once
/// The 1-D search for a model's nonlinear time constant or width (a lag's tau, a hysteresis
/// width w) with every linear coefficient profiled out (model/poly_fit.h): f(x) is the residual
/// sum of squares of the linear fit at x.
///
///   1. a grid of `grid_points` values log-spaced over [lo, hi];
///   2. golden-section search on log x between the grid neighbours of the best grid point,
///      until the bracket is narrower than `tolerance` in log x (1e-3: 0.1 %).
///
/// A profile with several local minima is searched around the best grid point only; the grid
/// is fine enough (16 points over a span of 1000: 58 % apart) that the thermal profiles met so
/// far have one minimum per grid cell.

#include <functional>
#include <string>
#include <vector>

namespace rlg::model {

struct ProfileOptions {
  int grid_points = 16;
  double tolerance = 1e-3;
  bool IsValid(std::string* error) const;
};

struct ProfileResult {
  double x = 0.0;   ///< the minimiser found
  double f = 0.0;   ///< f(x)
  bool at_bound = false;  ///< the best grid point was the first or last: the minimum may lie beyond
  std::vector<double> grid_x, grid_f;
};

/// Minimises f over [lo, hi] (0 < lo < hi). InputError for invalid options or bounds; a
/// non-finite f(x) counts as +inf.
ProfileResult MinimizeOnLogScale(const std::function<double(double)>& f, double lo, double hi,
                                 const ProfileOptions& options = {});

/// Step 2 alone: golden-section search on log x over [lo, hi] (a bracket known to hold the
/// minimum, e.g. a grid point's neighbours), to `tolerance` in log x. Returns the best point seen,
/// `start` (with f(start) = f_start) included.
ProfileResult GoldenOnLogScale(const std::function<double(double)>& f, double lo, double hi, double start,
                               double f_start, double tolerance = 1e-3);

/// The grid of step 1: `points` values log-spaced over [lo, hi].
std::vector<double> LogGrid(double lo, double hi, int points);

}  // namespace rlg::model
