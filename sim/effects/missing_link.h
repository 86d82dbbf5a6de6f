#pragma once
/// thermal.missing_link: a conductance the nominal network lacks, between two nodes or a node
/// and ambient.
///
///   C_a dT_a/dt += G (T_b - T_a),   C_b dT_b/dt += G (T_a - T_b)
///
/// G in W/K (conductance_W_per_K). Target: "a-b" or "a-ambient".

#include "sim/effect.h"

namespace rlg::sim {

class MissingLinkEffect final : public Effect {
 public:
  MissingLinkEffect();
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
  Appended AppendsToNetwork() const override { return {0, 1, 0}; }
};

}  // namespace rlg::sim
