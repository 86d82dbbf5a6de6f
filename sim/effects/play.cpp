#include "sim/effects/play.h"

#include "sim/limits.h"

namespace rlg::sim {

PlayEffect::PlayEffect()
    : Effect("bias.play", EffectKind::kBias,
             {{"k_dph_per_C", "°/h/°C", false, -0.5, 0.5,
               "[est] the coefficient of the temperature the bias follows through the play; beyond the default "
               "gyro's largest coefficient (Langmuir, 0.45 °/h/°C) it needs a reason",
               -limits::kMaxBiasPerC, limits::kMaxBiasPerC, std::nullopt},
              {"width_C", "°C", true, 0.05, 20.0,
               "[est] a loop narrower than a sensor's resolution cannot be seen, and one wider than 20 °C would be "
               "a quarter of a -30...+50 °C calibration span without reversing: a different cause",
               0.0, limits::kTemperatureSpan_C, std::nullopt},
              {"reference_C", "°C", false, limits::kMinTemperature_C, limits::kMaxTemperature_C,
               "[src] the temperatures the tidy CSV holds (docs/data-format.md)", limits::kMinTemperature_C,
               limits::kMaxTemperature_C, 20.0, /*reference=*/true}}) {}

void PlayEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  gyro.bias.play.push_back({ResolveNode(gyro, target, false), p.at("k_dph_per_C"), p.at("width_C"), p.at("reference_C")});
}

}  // namespace rlg::sim
