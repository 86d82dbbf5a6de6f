#pragma once
/// Multi-start for the refit of a thermal candidate (stage 4). A candidate's
/// refit starts where the linearised screening points (statistics/screen.h), which for a size
/// that spans decades (a conductance of 1e-4 to 10 W/K, a radiating area, a lag, a mass) can be
/// decades from the optimum: local least squares from there stopped at 0.0058 W/K for a link
/// of 0.01 W/K, and at 5 J/K and 0.002 W/K for a mass of 147 J/K and 0.47 W/K. Before the
/// local fit, each positive parameter is scanned on a grid in log space over its plausible
/// range, one parameter at a time with the others held (coordinate search), and the best point
/// of the grid or the screening start is where the local fit begins.
///
/// Pure: the objective is a callback (the engine's chi² of the noise-free simulation plus any
/// prior, +infinity where the simulation fails).

#include <functional>
#include <vector>

namespace rlg::diagnosis {

/// Points from lo to hi (0 < lo < hi) equally spaced in log10 at `per_decade` points a decade
/// or slightly more, always both ends: ceil(per_decade * log10(hi / lo)) + 1 points.
std::vector<double> LogGrid(double lo, double hi, double per_decade);

struct SearchResult {
  std::vector<double> x;  ///< the best point evaluated
  double value = 0.0;     ///< the objective there
  int evaluations = 0;
};

/// Coordinate search over grids: starting from x0 (evaluated first), for `passes` passes and
/// for each coordinate i in turn, evaluates the objective with x[i] set to every value of
/// grids[i] (the other coordinates at the best point so far) and moves to the best; then, with
/// two or more gridded coordinates, along the diagonal: every gridded coordinate multiplied by
/// each of `diagonal` (points outside a grid's range skipped). Coordinate moves alone stall in
/// a diagonal valley (a mass and its conductance, which trade along a fixed time constant):
/// each move off the valley's floor costs more than the floor falls. An empty grid leaves its
/// coordinate alone. Non-finite values never win; x0 stands if nothing beats it.
/// Precondition: grids.size() == x0.size().
SearchResult CoordinateSearch(const std::function<double(const std::vector<double>&)>& objective,
                              const std::vector<double>& x0, const std::vector<std::vector<double>>& grids, int passes,
                              const std::vector<double>& diagonal = {});

}  // namespace rlg::diagnosis
