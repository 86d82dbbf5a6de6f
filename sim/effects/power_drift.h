#pragma once
/// thermal.power_drift: the heat source depositing on a node dissipates a power that depends
/// on that node's temperature (a discharge's voltage and current drift as it warms):
///
///   P = P0 (1 + g (T_n - T_ref))
///
/// g in 1/°C (g_per_C), T_ref in °C (reference_C, default 20, held fixed when fitted). Target:
/// a node some source deposits power on; the first such source drifts.

#include "sim/effect.h"

namespace rlg::sim {

class PowerDriftEffect final : public Effect {
 public:
  PowerDriftEffect();
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
};

}  // namespace rlg::sim
