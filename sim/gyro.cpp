#include "sim/gyro.h"

#include <fmt/format.h>

#include "sim/effect_registry.h"
#include "sim/errors.h"

namespace rlg::sim {

const std::vector<std::string>& EffectNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const auto& e : Effects()) v.push_back(e->name());
    return v;
  }();
  return names;
}

int GyroConfig::FindSensor(const std::string& channel) const {
  for (size_t i = 0; i < sensors.size(); ++i)
    if (sensors[i].channel == channel) return static_cast<int>(i);
  return -1;
}

void ApplyEffect(const EffectSpec& e, GyroConfig& gyro) {
  const Effect& effect = RequireEffect(e.name);
  ParameterMap p;
  for (const auto& param : effect.parameters()) {
    auto it = e.parameters.find(param.name);
    if (it != e.parameters.end()) {
      p[param.name] = it->second;
    } else if (!param.default_value) {
      throw InputError(fmt::format("effect '{}' needs parameter '{}'", e.name, param.name));
    } else {
      p[param.name] = *param.default_value;
    }
  }
  for (const auto& [key, v] : e.parameters) {
    if (!p.count(key)) throw InputError(fmt::format("effect '{}' has no parameter '{}'", e.name, key));
  }
  effect.Apply(e.target, p, gyro);
  gyro.effects.push_back(e);
}

}  // namespace rlg::sim
