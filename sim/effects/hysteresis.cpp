#include "sim/effects/hysteresis.h"

#include <memory>

#include "sim/limits.h"

namespace rlg::sim {
namespace {

// [est] A typical size of k_heating - k_cooling: a loop 0.4 °/h wide after a 40 °C ramp up and
// down, above the default gyro's intrinsic b1 (0.006 °/h/°C).
constexpr double kTypical = 0.01;
const char* const kDifference = "k_heating_minus_cooling_dph_per_C";

EffectParameter Coefficient(const std::string& name, double start) {
  return {name, "°/h/°C", false, -0.5, 0.5,
          "[est] bias-temperature correlation changes with run time and direction (Acta Optica Sinica 29(4), "
          "2009, docs/physics.md); a coefficient beyond the default gyro's largest (Langmuir, 0.45 °/h/°C) needs a reason",
          -limits::kMaxBiasPerC, limits::kMaxBiasPerC, std::nullopt, start};
}

}  // namespace

HysteresisEffect::HysteresisEffect()
    : Effect("bias.hysteresis", EffectKind::kBias,
             {Coefficient("k_heating_dph_per_C", kTypical), Coefficient("k_cooling_dph_per_C", 0.0)}) {}

std::vector<std::string> HysteresisEffect::Targets(const TargetSpace& space) const {
  std::vector<std::string> out;
  for (int node = 0; node < space.nodes; ++node) out.push_back(space.gyro.network.nodes[node].name);
  return out;
}

void HysteresisEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  gyro.bias.hysteresis.push_back(
      {ResolveNode(gyro, target, false), p.at("k_heating_dph_per_C"), p.at("k_cooling_dph_per_C")});
}

std::vector<BiasRegressor> HysteresisEffect::Regressors(const TargetSpace& space,
                                                        const std::vector<const Eigen::MatrixXd*>& T_runs, const ColumnGain&) const {
  // Heating increments of the node since power-on, from the tracks given. Cooling increments
  // are the node's change minus these, already spanned by the baseline's linear term. The
  // column shares its data by value: it outlives this call when a candidate is accepted.
  std::vector<BiasRegressor> out;
  for (int node = 0; node < space.nodes; ++node) {
    auto heat = std::make_shared<std::vector<std::vector<double>>>(T_runs.size());
    for (size_t r = 0; r < T_runs.size(); ++r) {
      const Eigen::MatrixXd& T = *T_runs[r];
      auto& h = (*heat)[r];
      h.resize(static_cast<size_t>(T.cols()));
      double last = h.empty() ? 0.0 : T(node, 0), accumulated = 0.0;
      for (size_t k = 0; k < h.size(); ++k) h[k] = Bias_dph(1.0, 0.0, T(node, static_cast<Eigen::Index>(k)), last, accumulated);
    }
    out.push_back({space.gyro.network.nodes[node].name,
                   [heat](const NodeTrack&, size_t k, int r) { return (*heat)[static_cast<size_t>(r)][k]; },
                   [](double c) { return ParameterMap{{kDifference, c}}; }});
  }
  return out;
}

ParameterMap HysteresisEffect::FromReported(const ParameterMap& reported) const {
  return {{"k_heating_dph_per_C", reported.at(kDifference)}, {"k_cooling_dph_per_C", 0.0}};
}

double HysteresisEffect::Implausibility(const ParameterMap& reported) const {
  return Relative(reported, kDifference, kTypical);
}

}  // namespace rlg::sim
