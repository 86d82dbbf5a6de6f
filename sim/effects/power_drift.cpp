#include "sim/effects/power_drift.h"

#include <fmt/format.h>

#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::sim {

PowerDriftEffect::PowerDriftEffect()
    : Effect("thermal.power_drift", EffectKind::kThermal,
             {{"g_per_C", "1/°C", false, -0.01, 0.01,
               "[est] a current-regulated gas discharge's dissipation drifts well under 1 %/°C (sim/limits.h), and so "
               "does a transistor heater at a set current (TCLab's: its power moves only with the transistor's "
               "voltage drop); a fit beyond 1 %/°C is standing in for something else",
               -limits::kMaxRelativePerC, limits::kMaxRelativePerC, std::nullopt},
              {"reference_C", "°C", false, limits::kMinTemperature_C, limits::kMaxTemperature_C,
               "[src] the temperatures the tidy CSV holds (docs/data-format.md)", limits::kMinTemperature_C,
               limits::kMaxTemperature_C, 20.0, /*reference=*/true}}) {}

void PowerDriftEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  const int node = ResolveNode(gyro, target, false);
  for (auto& src : gyro.network.sources) {
    bool deposits = false;
    for (const auto& sh : src.shares)
      if (sh.first == node && sh.second > 0.0) deposits = true;
    if (!deposits) continue;
    src.drift_node = node;
    src.drift_per_K = p.at("g_per_C");
    src.drift_reference_C = p.at("reference_C");
    return;
  }
  throw InputError(fmt::format("thermal.power_drift: no heat source deposits power on '{}'", target));
}

}  // namespace rlg::sim
