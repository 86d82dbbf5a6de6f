#pragma once
/// A gyro: thermal network, temperature sensors, bias physics, noise, and the optional
/// catalog effects (scenarios/README.md, Effects). Read from a TOML gyro file by io/gyro_file.h.
///
/// Effects are configuration: ApplyEffect turns an EffectSpec into network elements, sensor
/// properties or bias terms through the effect's object in the catalog (sim/effect_registry.h),
/// so neither this file nor the simulator has per-effect branches.

#include <map>
#include <string>
#include <vector>

#include "sim/bias_model.h"
#include "sim/noise.h"
#include "sim/thermal_network.h"

namespace rlg::sim {

/// Fixed effect names of scenarios/README.md, Effects (without "none").
const std::vector<std::string>& EffectNames();

struct EffectSpec {
  std::string name;                      ///< e.g. "bias.temperature_rate"
  std::string target;                    ///< channel "T1", node "block", or pair "anode-cabinet"
  std::map<std::string, double> parameters;
};

struct SensorSpec {
  std::string channel;  ///< "T1", "T2", ... or a free name like "T_mirror"
  int node = 0;
  SensorNoiseParams noise;
  double offset_C = 0.0;        ///< sensor.offset
  /// sensor.lag, one first-order stage per effect applied, in series from the node (a sensor in
  /// a housing glued to the block lags twice); empty = none.
  std::vector<double> lag_time_constants_s;
};

struct GyroConfig {
  std::string name;
  NetworkSpec network;
  std::vector<SensorSpec> sensors;  ///< output order
  BiasParams bias;
  GyroNoiseParams noise;
  std::vector<EffectSpec> effects;  ///< as listed; already applied to the fields above
  /// How well the nominal thermal parameters are known (1 sigma, relative): the prior of
  /// `diagnose`'s calibration. [calibration] relative_uncertainty in the gyro file.
  double calibration_uncertainty = 0.05;

  /// Index of the sensor for `channel`, or -1.
  int FindSensor(const std::string& channel) const;
};

/// Applies a catalog effect to `gyro` and records it in gyro.effects. InputError (plain
/// message, no location) for an unknown name, target or parameter.
void ApplyEffect(const EffectSpec& effect, GyroConfig& gyro);

}  // namespace rlg::sim
