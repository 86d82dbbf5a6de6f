#include "sim/effects/sensor_offset.h"

#include "sim/limits.h"

namespace rlg::sim {

SensorOffsetEffect::SensorOffsetEffect()
    : Effect("sensor.offset", EffectKind::kSensor,
             {{"offset_C", "°C", false, -3.0, 3.0,
               "[est] a calibrated platinum RTD is within ±0.3 °C (IEC 60751 class B at 0 °C); an uncalibrated IC "
               "sensor within ±2 °C (the TMP36 datasheet: ±1 °C at 25 °C, ±2 °C over its range)",
               -limits::kMaxOffset, limits::kMaxOffset, std::nullopt}}) {}

void SensorOffsetEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  gyro.sensors[RequireSensor(gyro, target)].offset_C += p.at("offset_C");
}

}  // namespace rlg::sim
