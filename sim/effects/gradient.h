#pragma once
/// bias.gradient: a bias term proportional to the temperature difference of two nodes that
/// the nominal bias model omits,
///
///   B = k (T_a - T_b)
///
/// k in °/h/°C (k_dph_per_C), T in °C. Target: a pair "a-b" (channels name their nodes).

#include "sim/effect.h"

namespace rlg::sim {

class GradientEffect final : public Effect {
 public:
  GradientEffect();
  /// The term (°/h): what BiasModel adds, and at k = 1 the regressor `diagnose` fits.
  static double Bias_dph(double k_dph_per_C, double T_a_C, double T_b_C) { return k_dph_per_C * (T_a_C - T_b_C); }
  /// Every pair of nodes that is not already a Langmuir gradient of the bias model.
  std::vector<std::string> Targets(const TargetSpace& space) const override;
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
  std::vector<BiasRegressor> Regressors(const TargetSpace& space,
                                        const std::vector<const Eigen::MatrixXd*>& T_runs,
                                        const ColumnGain& gain) const override;
  /// Its term reads the tracks alone.
  bool ComputedFromTracks() const override { return true; }
  double Implausibility(const ParameterMap& reported) const override;
  /// Gradients of different pairs part where those nodes heat differently.
  std::string SeparationAdvice(const std::set<std::string>& tied_causes, bool ambient_logged) const override;
};

}  // namespace rlg::sim
