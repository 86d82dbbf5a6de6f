#include "sim/effects/sensor_lag.h"

#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::sim {

SensorLagEffect::SensorLagEffect()
    : Effect("sensor.lag", EffectKind::kSensor,
             {{"time_constant_s", "s", true, 0.1, 600.0,
               "[est] a bare thermocouple or thin-film RTD (~0.1 s) to a sensor in a housing or on a heat sink, "
               "glued or clamped (minutes)",
               limits::kMinLag, limits::kMaxLag, std::nullopt}}) {}

void SensorLagEffect::Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const {
  const int s = RequireSensor(gyro, target);
  if (!(p.at("time_constant_s") > 0.0)) throw InputError("sensor.lag needs time_constant_s > 0");
  // A lag applied to a sensor that already lags is a second stage in series, not a replacement:
  // `diagnose` searched for a second lag on refgen's already-lagged T2 by replacing its 30 s
  // with 5 s, which screened at no gain, and named an offset instead.
  gyro.sensors[s].lag_time_constants_s.push_back(p.at("time_constant_s"));
}

}  // namespace rlg::sim
