#include "sim/effects/mode_hop.h"

#include <fmt/format.h>
#include <memory>

#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::sim {
namespace {

// [est] A typical step: a few times a navigation-grade gyro's 100 s noise (PHYSICS.md).
constexpr double kTypical = 0.05;

}  // namespace

ModeHopEffect::ModeHopEffect()
    : Effect("bias.mode_hop", EffectKind::kBias,
             {{"step_dph", "°/h", false, -1.0, 1.0,
               "[est] a hop to an adjacent mode makes the bias jump (Infrared & Laser Eng. 2014(2), PHYSICS.md); a "
               "step beyond 1 °/h would exceed the paper's whole run-mean bias (0.63-1.42 °/h)",
               -limits::kMaxNoise_dph, limits::kMaxNoise_dph, std::nullopt, kTypical},
              {"range_modes", "modes", true, 0.5, 3.0,
               "[est] above 0.5 a mode is held at all (and hops show hysteresis); a mirror transducer travels a few "
               "wavelengths",
               0.0, limits::kMaxRangeModes, 0.6, 0.6, EffectParameter::Fit::kShape},
              {"mode_spacing_C", "°C", true, 15.0, 70.0,
               "[est] one wavelength of path change takes 15-70 K of block excursion for a 43 cm path (PHYSICS.md); "
               "0 in a file: lambda / (L alpha) from the cavity (29 K for the default gyro)",
               0.0, limits::kTemperatureSpan_C, 0.0, 30.0, EffectParameter::Fit::kShape}}) {}

std::vector<std::string> ModeHopEffect::Targets(const TargetSpace& space) const {
  return {NodeTarget(space.gyro, space.gyro.bias.node)};
}

void ModeHopEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  auto& bias = gyro.bias;
  const int node = ResolveNode(gyro, target, false);
  if (node != bias.node) {
    throw InputError(fmt::format("bias.mode_hop acts on the bias node '{}' (the path-length control follows it)",
                                 gyro.network.nodes[bias.node].name));
  }
  if (!(p.at("range_modes") > 0.5)) throw InputError("bias.mode_hop needs range_modes > 0.5");
  bias.mode_hops = true;
  bias.mode_hop_step_dph = p.at("step_dph");
  bias.mode_hop_range_modes = p.at("range_modes");
  if (p.at("mode_spacing_C") > 0.0) bias.mode_spacing_C = p.at("mode_spacing_C");
}

std::vector<BiasRegressor> ModeHopEffect::Regressors(const TargetSpace& space,
                                                     const std::vector<const Eigen::MatrixXd*>& T_runs) const {
  // The mode index for a grid of half-ranges, each run locked at its first sample; the column
  // shares its data by value: it outlives this call when a candidate is accepted.
  const BiasParams& bias = space.gyro.bias;
  const double spacing = bias.ModeSpacing_C();
  const double plc = bias.plc_dph_per_wavelength;
  std::vector<BiasRegressor> out;
  for (double range : {0.55, 0.6, 0.7, 0.8, 0.9}) {
    auto modes = std::make_shared<std::vector<std::vector<double>>>(T_runs.size());
    bool any = false;
    for (size_t r = 0; r < T_runs.size(); ++r) {
      const Eigen::MatrixXd& T = *T_runs[r];
      auto& m = (*modes)[r];
      m.resize(static_cast<size_t>(T.cols()));
      const double lock = m.empty() ? 0.0 : T(bias.node, 0);
      int mode = 0;
      for (size_t k = 0; k < m.size(); ++k) {
        PathLengthTravel(T(bias.node, static_cast<Eigen::Index>(k)), lock, spacing, range, mode);
        m[k] = Bias_dph(1.0, mode);
        any = any || mode != 0;
      }
    }
    if (!any) continue;
    out.push_back({NodeTarget(space.gyro, bias.node),
                   [modes](const NodeTrack&, size_t k, int r) { return (*modes)[static_cast<size_t>(r)][k]; },
                   [plc, range](double c) {
                     // The PLC term resets with each hop, so the step seen is step - k_plc.
                     return ParameterMap{{"step_dph", c + plc}, {"range_modes", range}};
                   }});
  }
  return out;
}

double ModeHopEffect::Implausibility(const ParameterMap& reported) const {
  return Relative(reported, "step_dph", kTypical);
}

}  // namespace rlg::sim
