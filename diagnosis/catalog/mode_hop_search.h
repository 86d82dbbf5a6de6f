#pragma once
/// The search of a mode hop's shape (bias.mode_hop, sim/effects/mode_hop.h): the step size is a
/// linear coefficient, but where the bias steps depends on the mode spacing dT_mode (°C), the
/// path-length control's range (modes) and, for a PLC that locks by absolute temperature, the
/// centre (°C), none of which a gyro file can fix. Its table entry (effect_search.h) returns,
/// per power-on form (every run centred on a mode, and locked by an absolute centre), the best
/// shape by the column gain: a grid over spacing (log, 3-150 °C, within what the tracks' span
/// can show), centre (a phase grid of the spacing) and range (0.5-0.9), then a pattern search
/// from the best grid point of each of the three best spacings, the best of those refined on.

#include <Eigen/Core>
#include <vector>

#include "diagnosis/catalog/effect_search.h"

namespace rlg::diagnosis {

/// The shape of the steps: what the step size multiplies.
struct ModeHopShape {
  double spacing_C = 0.0;  ///< dT_mode
  double range_modes = 0.6;
  double centre_C = 0.0;   ///< used when `centred` is false
  bool centred = true;     ///< every run powers on centred on a mode
};

/// The mode index m along run r's bias-node track (row `node` of *T_runs[r]), per run, and
/// whether some run hops within itself (a column that is constant in every run is taken up by
/// the runs' offsets).
std::vector<std::vector<double>> ModeIndex(const std::vector<const Eigen::MatrixXd*>& T_runs, int node,
                                          const ModeHopShape& shape, bool* hops);

/// The same for many shapes on the same tracks (the shape search asks for hundreds): the least
/// and greatest bias-node temperature of every stretch of kStretch samples, kept, tell whether
/// a shape's travel stays within its range over the stretch, and then the stretch keeps its mode
/// without a look at its samples. The same numbers as sample by sample: the travel
/// (T - T_lock) / dT_mode - m is monotone in T, rounding included.
class ModeTracks {
 public:
  static constexpr size_t kStretch = 64;
  /// Keeps the pointers: the tracks must outlive this.
  ModeTracks(const std::vector<const Eigen::MatrixXd*>& T_runs, int node);
  std::vector<std::vector<double>> ModeIndex(const ModeHopShape& shape, bool* hops) const;

 private:
  std::vector<const Eigen::MatrixXd*> T_runs_;
  int node_;
  std::vector<std::vector<std::pair<double, double>>> extremes_;  // per run, per stretch: least, greatest
};

}  // namespace rlg::diagnosis
