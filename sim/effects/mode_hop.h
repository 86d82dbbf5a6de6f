#pragma once
/// bias.mode_hop: the path-length control (PLC) holds the cavity on one mode by moving a
/// mirror, over a limited travel; when the block's excursion takes it past that range it
/// resets by one mode, and the bias steps:
///
///   u = (T_b - T_lock) / dT_mode - m,   m -> m +- 1 whenever |u| > range,   B = step m
///
/// step in °/h (step_dph), range in modes (range_modes, default 0.6; 0.5: hops without
/// hysteresis, the bias a staircase of T_b, the same heating and cooling), dT_mode in °C
/// (mode_spacing_C, default 0: lambda / (L alpha) from the cavity). T_b is the bias node's
/// temperature. Power-on: without centre_C every run locks centred on a mode (T_lock = T_b(0),
/// m = 0); with centre_C (°C, a T_b at which a mode sits at the centre of the travel) the PLC
/// locks on the mode nearest its centre, T_lock = centre_C and m = m0 (PowerOn, bias_model.h),
/// so the runs' phases follow from their absolute temperatures. Target: the bias node.
///
/// Zerodur's expansion coefficient is uncertain to more than its value, so a gyro file cannot
/// fix dT_mode, and the power-on phase is unknown: `diagnose` searches spacing, centre and range
/// (diagnosis/catalog/mode_hop_search.h).

#include "sim/effect.h"

namespace rlg::sim {

class ModeHopEffect final : public Effect {
 public:
  ModeHopEffect();
  /// The term (°/h) at mode index m: what BiasModel adds. The travel and m come from
  /// PathLengthTravel (sim/bias_model.h).
  static double Bias_dph(double step_dph, int mode) { return step_dph * mode; }
  void Apply(const std::string& target, const ParameterMap& p, GyroConfig& gyro) const override;
};

}  // namespace rlg::sim
