#pragma once
/// bias.mode_hop: the path-length control (PLC) holds the cavity on one mode by moving a
/// mirror, over a limited travel; when the block's excursion takes it past that range it
/// resets by one mode, and the bias steps:
///
///   u = (T_b - T_lock) / dT_mode - m,   m -> m +- 1 whenever |u| > range,   B = step m
///
/// step in °/h (step_dph), range in modes (range_modes, default 0.6: > 0.5), dT_mode in °C
/// (mode_spacing_C, default 0: lambda / (L alpha) from the cavity). T_b is the bias node's
/// temperature and T_lock its value at power-on. Target: the bias node (its channel or name).

#include "sim/effect.h"

namespace rlg::sim {

class ModeHopEffect final : public Effect {
 public:
  ModeHopEffect();
  /// The term (°/h) at mode index m: what BiasModel adds, and at step = 1 the regressor
  /// `diagnose` fits. The travel and m come from PathLengthTravel (sim/bias_model.h).
  static double Bias_dph(double step_dph, int mode) { return step_dph * mode; }
  /// The bias node.
  std::vector<std::string> Targets(const TargetSpace& space) const override;
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
  /// One per PLC half-range of a grid (0.55 ... 0.9 modes) at which some run hops.
  std::vector<BiasRegressor> Regressors(const TargetSpace& space,
                                        const std::vector<const Eigen::MatrixXd*>& T_runs) const override;
  double Implausibility(const ParameterMap& reported) const override;
};

}  // namespace rlg::sim
