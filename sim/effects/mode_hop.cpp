#include "sim/effects/mode_hop.h"

#include <fmt/format.h>

#include <limits>

#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::sim {

ModeHopEffect::ModeHopEffect()
    : Effect("bias.mode_hop", EffectKind::kBias,
             {{"step_dph", "°/h", false, -1.0, 1.0,
               "[est] a hop to an adjacent mode makes the bias jump (Infrared & Laser Eng. 2014(2), docs/physics.md); a "
               "step beyond 1 °/h would exceed the paper's whole run-mean bias (0.63-1.42 °/h)",
               -limits::kMaxNoise_dph, limits::kMaxNoise_dph, std::nullopt},
              {"range_modes", "modes", true, 0.5, 3.0,
               "[est] at 0.5 a mode is held up to the next one's centre (hops without hysteresis), above it hops "
               "show hysteresis; a mirror transducer travels a few wavelengths",
               0.0, limits::kMaxRangeModes, 0.6},
              {"mode_spacing_C", "°C", true, 15.0, 70.0,
               "[est] one wavelength of path change takes 15-70 K of block excursion for a 43 cm path (docs/physics.md); "
               "0 in a file: lambda / (L alpha) from the cavity (29 K for the default gyro)",
               0.0, limits::kTemperatureSpan_C, 0.0},
              {"centre_C", "°C", false, limits::kMinTemperature_C, limits::kMaxTemperature_C,
               "[est] a bias-node temperature at which a mode sits at the centre of the PLC travel: any temperature "
               "(modes repeat every mode_spacing_C); not given: each run powers on centred on a mode",
               limits::kMinTemperature_C, limits::kMaxTemperature_C, std::numeric_limits<double>::quiet_NaN()}}) {}

void ModeHopEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  auto& bias = gyro.bias;
  const int node = ResolveNode(gyro, target, false);
  if (node != bias.node) {
    throw InputError(fmt::format("bias.mode_hop acts on the bias node '{}' (the path-length control follows it)",
                                 gyro.network.nodes[bias.node].name));
  }
  if (!(p.at("range_modes") >= 0.5)) throw InputError("bias.mode_hop needs range_modes >= 0.5");
  bias.mode_hops = true;
  bias.mode_hop_step_dph = p.at("step_dph");
  bias.mode_hop_range_modes = p.at("range_modes");
  if (p.at("mode_spacing_C") > 0.0) bias.mode_spacing_C = p.at("mode_spacing_C");
  bias.mode_hop_centre_C = p.at("centre_C");  // NaN when not given: centred power-on
}

}  // namespace rlg::sim
