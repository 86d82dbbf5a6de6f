// Multi-start for thermal refits (diagnosis/statistics/multistart.h): the log grid's points, and the
// coordinate search on objectives with known minima, including one two decades from the start
// with a local minimum beside the start (where a local fit from the start stops).

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "diagnosis/statistics/multistart.h"

namespace rlg::diagnosis {
namespace {

TEST(LogGrid, SpansTheRangeAtTheAskedDensityInLogSpace) {
  const std::vector<double> g = LogGrid(1e-4, 10.0, 2.0);  // 5 decades at 2 a decade: 11 points
  ASSERT_EQ(g.size(), 11u);
  EXPECT_EQ(g.front(), 1e-4);
  EXPECT_EQ(g.back(), 10.0);
  for (size_t k = 1; k < g.size(); ++k)  // equal ratios of sqrt(10), to round-off of pow
    EXPECT_NEAR(g[k] / g[k - 1], std::sqrt(10.0), 1e-12);
  // 3.78 decades (a lag of 0.1 to 600 s) need 8 steps, each 0.47 of a decade.
  const std::vector<double> lag = LogGrid(0.1, 600.0, 2.0);
  ASSERT_EQ(lag.size(), 9u);
  EXPECT_NEAR(std::log10(lag[1] / lag[0]), std::log10(6000.0) / 8.0, 1e-12);
}

TEST(CoordinateSearch, FindsAMinimumTwoDecadesFromTheStartPastALocalOne) {
  // In u = log10(x): a shallow local minimum at u = -2 (the start) and the global one, deeper,
  // at u = 0, two decades away. A local fit from the start would stay at 0.01.
  auto f = [](const std::vector<double>& x) {
    const double u = std::log10(x[0]);
    return 5.0 - 2.0 * std::exp(-std::pow((u + 2.0) / 0.3, 2)) - 5.0 * std::exp(-std::pow(u / 0.5, 2));
  };
  const SearchResult r = CoordinateSearch(f, {0.01}, {LogGrid(1e-4, 10.0, 2.0)}, 1);
  EXPECT_EQ(r.x[0], 1.0);  // a grid point: 1e-4 x sqrt(10)^8, within round-off of 1
  EXPECT_EQ(r.evaluations, 12);  // the start and 11 grid points
  EXPECT_LT(r.value, f({0.01}));
}

TEST(CoordinateSearch, TheDiagonalFollowsAValleyOfTwoTradingParameters) {
  // A valley along log c - log g = 2 (a mass and its conductance trade: time constant c/g),
  // its floor falling 0.1 per decade squared towards c = 100, g = 1; the start (1, 1e-3) is far
  // from both. The coordinates alone reach the floor and stall there (a half-decade move off
  // it costs 2.5, the floor falls by at most 0.4 over a grid step): (1, 0.01).
  auto f = [](const std::vector<double>& x) {
    const double a = std::log10(x[0]), b = std::log10(x[1]);
    return 10.0 * std::pow(a - b - 2.0, 2) + 0.1 * std::pow(a - 2.0, 2);
  };
  const std::vector<std::vector<double>> grids = {LogGrid(1.0, 1000.0, 2.0), LogGrid(1e-4, 10.0, 2.0)};
  const SearchResult stalled = CoordinateSearch(f, {1.0, 1e-3}, grids, 2);
  EXPECT_NEAR(std::log10(stalled.x[0]) - std::log10(stalled.x[1]), 2.0, 1e-9);  // on the floor
  EXPECT_NEAR(std::log10(stalled.x[0]), 0.0, 1e-9);                            // but stalled
  const std::vector<double> diagonal = LogGrid(0.01, 100.0, 2.0);  // two decades either way
  const SearchResult moved = CoordinateSearch(f, {1.0, 1e-3}, grids, 2, diagonal);
  // Grid points are exact powers of sqrt(10) to round-off of pow: 1e-9 in log10.
  EXPECT_NEAR(std::log10(moved.x[0]), 2.0, 1e-9);
  EXPECT_NEAR(std::log10(moved.x[1]), 0.0, 1e-9);
  EXPECT_LT(moved.value, 1e-12);
}

TEST(CoordinateSearch, NonFiniteValuesNeverWinAndAnEmptyGridHoldsItsCoordinate) {
  auto f = [](const std::vector<double>& x) {
    return x[0] > 5.0 ? std::numeric_limits<double>::quiet_NaN() : std::abs(x[0] - 3.0) + std::abs(x[1]);
  };
  const SearchResult r = CoordinateSearch(f, {1.0, 2.0}, {{2.0, 3.0, 10.0}, {}}, 1);
  EXPECT_EQ(r.x, (std::vector<double>{3.0, 2.0}));
  EXPECT_EQ(r.value, 2.0);
}

}  // namespace
}  // namespace rlg::diagnosis
