#include "sim/effect_registry.h"

#include <fmt/format.h>

#include "sim/effects/gradient.h"
#include "sim/effects/hysteresis.h"
#include "sim/effects/missing_link.h"
#include "sim/effects/missing_mass.h"
#include "sim/effects/mode_hop.h"
#include "sim/effects/play.h"
#include "sim/effects/power_drift.h"
#include "sim/effects/radiation.h"
#include "sim/effects/sensor_lag.h"
#include "sim/effects/sensor_offset.h"
#include "sim/effects/temperature_rate.h"
#include "sim/errors.h"

namespace rlg::sim {

const std::vector<std::unique_ptr<const Effect>>& Effects() {
  static const std::vector<std::unique_ptr<const Effect>> effects = [] {
    std::vector<std::unique_ptr<const Effect>> v;
    // scenarios/README.md, Effects's order: `diagnose` tries them in it and reports them in it.
    v.push_back(std::make_unique<MissingMassEffect>());
    v.push_back(std::make_unique<MissingLinkEffect>());
    v.push_back(std::make_unique<PowerDriftEffect>());
    v.push_back(std::make_unique<RadiationEffect>());
    v.push_back(std::make_unique<SensorLagEffect>());
    v.push_back(std::make_unique<SensorOffsetEffect>());
    v.push_back(std::make_unique<TemperatureRateEffect>());
    v.push_back(std::make_unique<GradientEffect>());
    v.push_back(std::make_unique<HysteresisEffect>());
    v.push_back(std::make_unique<PlayEffect>());
    v.push_back(std::make_unique<ModeHopEffect>());
    return v;
  }();
  return effects;
}

const Effect* FindEffect(const std::string& name) {
  for (const auto& e : Effects())
    if (e->name() == name) return e.get();
  return nullptr;
}

const Effect& RequireEffect(const std::string& name) {
  if (const Effect* e = FindEffect(name)) return *e;
  throw InputError(fmt::format("unknown effect '{}'; the catalog (scenarios/README.md, Effects) has: {}", name,
                               fmt::join(EffectNames(), ", ")));
}

}  // namespace rlg::sim
