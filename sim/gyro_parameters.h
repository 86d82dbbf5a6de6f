#pragma once
/// The scalar parameters of a gyro by name, as the gyro file spells them: what a population's
/// part-to-part spread (sim/population.h) draws and what its per-gyro CSV lists.
///
///   nodes.<node>.heat_capacity_J_per_K           J/K
///   links.<a>-<b>.conductance_W_per_K            W/K     (<b> may be "ambient")
///   radiation.<a>-<b>.emissivity_area_m2         m²
///   sources.<source>.power_W                     W
///   sensors.<channel>.noise_C                    °C      (1 sigma of a reading)
///   sensors.<channel>.offset_C                   °C      (a reading's constant error)
///   bias.<key>                                   the [bias] scalars: b0_dph, b1_dph_per_C,
///                                                b2_dph_per_C2, langmuir_current_imbalance_mA,
///                                                langmuir_dph_per_mA,
///                                                langmuir_temperature_coeff_per_C,
///                                                plc_dph_per_wavelength, cte_per_C, path_length_m
///   bias.langmuir_gradient.<a>-<b>.k_dph_per_C   °/h/°C
///   noise.<key>                                  arw_deg_per_sqrt_h, bias_instability_dph,
///                                                rrw_deg_per_h_per_sqrt_h, turn_on_sigma_dph
///   <effect>.<target>.<parameter>                a bias effect of the gyro's [[effects]] as
///                                                written: bias.temperature_rate.T1.k_dph_per_C_per_min,
///                                                bias.gradient.<a>-<b>.k_dph_per_C,
///                                                bias.hysteresis.<node>.k_heating_dph_per_C (and
///                                                k_cooling_dph_per_C), bias.play.<node>.k_dph_per_C
///                                                and .width_C; not the held ones (reference_C).
///                                                Its range is what a gyro file may give it
///                                                (sim::EffectParameter file_lo, file_hi; > 0 for a
///                                                positive one); setting it sets the effect's term
///                                                and its [[effects]] record, so a drawn gyro is
///                                                written back as it simulates
///
/// A pattern may put `*` for the name part (nodes.*.heat_capacity_J_per_K): it stands for every
/// element of that kind, in the gyro's order. Only parameters the gyro has are listed (a link
/// the file does not declare has no conductance to spread).

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "sim/gyro.h"

namespace rlg::sim {

struct GyroParameter {
  std::string name;  ///< e.g. "nodes.block.heat_capacity_J_per_K"
  /// Smallest value the physics allows: 0 for the non-negative (noise levels, conductances),
  /// a tiny positive number for what must be positive (heat capacities, the path length), and
  /// -inf for signed coefficients and offsets.
  double lower;
  bool lower_open;  ///< the value must be > lower (heat capacities), not >= lower
  std::function<double(const GyroConfig&)> get;
  std::function<void(GyroConfig&, double)> set;
  /// Largest value allowed (inclusive): +inf but for effect parameters.
  double upper = std::numeric_limits<double>::infinity();
};

/// Every named scalar parameter of `gyro`, in the order of the table above.
std::vector<GyroParameter> GyroParameters(const GyroConfig& gyro);

/// The parameters a name or pattern stands for, in the gyro's order; empty when none matches.
std::vector<GyroParameter> MatchParameters(const GyroConfig& gyro, const std::string& pattern);

}  // namespace rlg::sim
