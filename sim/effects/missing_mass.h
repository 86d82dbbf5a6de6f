#pragma once
/// thermal.missing_mass: an uninstrumented heat capacity between two nodes (adds lag).
///
///   C_m dT_m/dt = G (T_a - T_m) + G (T_b - T_m)
///
/// A new node m of capacity C_m (heat_capacity_J_per_K, J/K) linked to both ends a and b with
/// conductance G each (conductance_W_per_K, W/K). Target: a pair of nodes "a-b" (a channel
/// names the node its sensor sits on). Preconditions: C_m > 0, G > 0.

#include "sim/effect.h"

namespace rlg::sim {

class MissingMassEffect final : public Effect {
 public:
  MissingMassEffect();
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
  Appended AppendsToNetwork() const override { return {1, 2, 0}; }
};

}  // namespace rlg::sim
