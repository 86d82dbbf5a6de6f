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
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
};

}  // namespace rlg::sim
