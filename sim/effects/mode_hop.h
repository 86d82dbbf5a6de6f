#pragma once
/// bias.mode_hop: the path-length control (PLC) holds the cavity on one mode by moving a
/// mirror, over a limited travel; when the block's excursion takes it past that range it
/// resets by one mode, and the bias steps:
///
///   u = (T_b - T_lock) / dT_mode - m,   m -> m +- 1 whenever |u| > range,   B = step m
///
/// step in °/h (step_dph), range in modes (range_modes, default 0.6; 0.5: hops without
/// hysteresis, the bias a staircase of T_b, the same heating and cooling), dT_mode in °C
/// (mode_spacing_C, default 0: lambda / (L alpha) from the cavity). T_b is the bias node's
/// temperature. Power-on: without centre_C every run locks centred on a mode (T_lock = T_b(0),
/// m = 0); with centre_C (°C, a T_b at which a mode sits at the centre of the travel) the PLC
/// locks on the mode nearest its centre, T_lock = centre_C and m = m0 (PowerOn, bias_model.h),
/// so the runs' phases follow from their absolute temperatures. Target: the bias node.
///
/// Zerodur's expansion coefficient is uncertain to more than its value, so a gyro file cannot
/// fix dT_mode, and the power-on phase is unknown: `diagnose` searches spacing, centre and range
/// (Regressors).

#include "sim/effect.h"

namespace rlg::sim {

class ModeHopEffect final : public Effect {
 public:
  ModeHopEffect();
  /// The term (°/h) at mode index m: what BiasModel adds, and at step = 1 the regressor
  /// `diagnose` fits. The travel and m come from PathLengthTravel (sim/bias_model.h).
  static double Bias_dph(double step_dph, int mode) { return step_dph * mode; }
  /// The shape of the steps: what the step size multiplies.
  struct Shape {
    double spacing_C = 0.0;  ///< dT_mode
    double range_modes = 0.6;
    double centre_C = 0.0;   ///< used when `centred` is false
    bool centred = true;     ///< every run powers on centred on a mode
  };
  /// The mode index m along run r's bias-node track (row `node` of *T_runs[r]), per run, and
  /// whether some run hops within itself (a column that is constant in every run is taken up
  /// by the runs' offsets).
  static std::vector<std::vector<double>> ModeIndex(const std::vector<const Eigen::MatrixXd*>& T_runs, int node,
                                                    const Shape& shape, bool* hops);
  /// The bias node.
  std::vector<std::string> Targets(const TargetSpace& space) const override;
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
  /// The best shape of each power-on form (centred, and locked by an absolute centre) by `gain`:
  /// a grid over spacing (log, 3-150 °C, within what the tracks' span can show), centre (a
  /// phase grid of the spacing) and range (0.5-0.9), then a pattern search from the best grid
  /// point of each of the three best spacings, the best of those refined on.
  std::vector<BiasRegressor> Regressors(const TargetSpace& space, const std::vector<const Eigen::MatrixXd*>& T_runs,
                                        const ColumnGain& gain) const override;
  double Implausibility(const ParameterMap& reported) const override;
};

}  // namespace rlg::sim
