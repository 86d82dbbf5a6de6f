#pragma once
/// thermal.radiation: radiative exchange of a node with another node or with ambient,
///
///   C_a dT_a/dt -= eps A sigma (T_a^4 - T_b^4)      (T in K, sigma = 5.67e-8 W/(m² K^4))
///
/// eps A in m² (emissivity_area_m2). Target: "a-b" or "a-ambient".

#include "sim/effect.h"

namespace rlg::sim {

class RadiationEffect final : public Effect {
 public:
  RadiationEffect();
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
  Appended AppendsToNetwork() const override { return {0, 0, 1}; }
};

}  // namespace rlg::sim
