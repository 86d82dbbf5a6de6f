#pragma once
/// sensor.lag: a temperature sensor that follows its node through a first-order lag,
///
///   tau dS/dt = T_node - S       (the channel reads S; the sensor draws no heat)
///
/// tau in s (time_constant_s), > 0. Target: a channel ("T2"). On a channel that already lags,
/// a second stage in series: tau2 dS2/dt = S - S2, the channel reads S2.

#include "sim/effect.h"

namespace rlg::sim {

class SensorLagEffect final : public Effect {
 public:
  SensorLagEffect();
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
};

}  // namespace rlg::sim
