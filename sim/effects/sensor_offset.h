#pragma once
/// sensor.offset: a constant calibration offset of a temperature sensor,
///
///   reading = T_node + offset
///
/// offset in °C (offset_C), either sign. Target: a channel ("T2").

#include "sim/effect.h"

namespace rlg::sim {

class SensorOffsetEffect final : public Effect {
 public:
  SensorOffsetEffect();
  /// Every channel with data.
  std::vector<std::string> Targets(const TargetSpace& space) const override;
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
  /// With the ambient unlogged, offsets on different channels and the ambient trade.
  std::string SeparationAdvice(const std::set<std::string>& tied_causes, bool ambient_logged) const override;
};

}  // namespace rlg::sim
