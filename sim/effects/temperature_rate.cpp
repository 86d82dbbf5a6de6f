#include "sim/effects/temperature_rate.h"

#include "sim/limits.h"

namespace rlg::sim {
namespace {

// [est] A typical size: 0.05 °/h per °C/min moves the bias by 0.05 °/h during a 1 °C/min
// ramp, a few times a navigation-grade gyro's 100 s noise (docs/physics.md).
constexpr double kTypical = 0.05;

}  // namespace

TemperatureRateEffect::TemperatureRateEffect()
    : Effect("bias.temperature_rate", EffectKind::kBias,
             {{"k_dph_per_C_per_min", "°/h per °C/min", false, -1.0, 1.0,
               "[est] dT/dt terms improve compensation (Sensors 20(2):377, 2020, docs/physics.md); beyond 1 °/h per "
               "°C/min a 1 °C/min ramp would move the bias by more than the paper's whole run-mean bias (0.63-1.42 "
               "°/h)",
               -limits::kMaxBiasPerRate, limits::kMaxBiasPerRate, std::nullopt, kTypical}}) {}

std::vector<std::string> TemperatureRateEffect::Targets(const TargetSpace& space) const {
  std::vector<std::string> out;
  for (int node = 0; node < space.nodes; ++node) out.push_back(NodeTarget(space.gyro, node));
  return out;
}

void TemperatureRateEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  gyro.bias.rate_terms.push_back({ResolveNode(gyro, target, false), p.at("k_dph_per_C_per_min")});
}

std::vector<BiasRegressor> TemperatureRateEffect::Regressors(const TargetSpace& space,
                                                             const std::vector<const Eigen::MatrixXd*>&, const ColumnGain&) const {
  std::vector<BiasRegressor> out;
  for (int node = 0; node < space.nodes; ++node) {
    out.push_back({NodeTarget(space.gyro, node),
                   [node](const NodeTrack& x, size_t k, int) {
                     return Bias_dph(1.0, x.Tdot(node, static_cast<Eigen::Index>(k)));
                   },
                   [](double c) { return ParameterMap{{"k_dph_per_C_per_min", c}}; }});
  }
  return out;
}

double TemperatureRateEffect::Implausibility(const ParameterMap& reported) const {
  return Relative(reported, "k_dph_per_C_per_min", kTypical);
}

}  // namespace rlg::sim
