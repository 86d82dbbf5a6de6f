#pragma once
/// The model under test in a diagnosis: the nominal gyro with its baseline knobs set, the
/// effects accepted so far (or a candidate's), and each run's nuisances.
///
/// A baseline knob is a scalar of the nominal thermal network the calibration fits: a node's
/// heat capacity (J/K), a link's conductance (W/K), a radiating pair's emissivity times area
/// (m²) or a source's gain (1 nominal). Build applies a Model to the nominal gyro:
///     g = nominal, knob_i(g) = base_i, then every effect applied in order (sim::ApplyEffect).

#include <functional>
#include <string>
#include <vector>

#include "diagnosis/statistics/identifiability.h"
#include "sim/effect.h"
#include "sim/gyro.h"

namespace rlg::diagnosis {

/// One scalar of the nominal gyro the calibration fits: its name ("C:block", "G:block-case",
/// "eA:block-ambient", "gain:heater1"), its nominal value (physical units), how to set it, and
/// what it is.
struct BaseKnob {
  std::string name;
  double nominal;
  std::function<void(sim::GyroConfig&, double)> set;
  KnobKind kind = KnobKind::kHeatCapacity;
  bool to_ambient = false;  ///< a link or radiating pair with ambient
  KnobLabel Label() const { return {name, kind, to_ambient}; }
};

/// Every heat capacity, every link and radiating pair with a positive value, and every source
/// that is switched on with a positive gain, in that order.
std::vector<BaseKnob> BaselineKnobs(const sim::GyroConfig& g);

struct Model {
  std::vector<double> base;              ///< baseline knob values (physical units)
  std::vector<sim::EffectSpec> effects;  ///< accepted (and candidate) effects with parameters
  std::vector<double> ambient;           ///< per run (°C), used where the ambient is unknown
  /// Per run, where the ambient is logged with noise: every state's start minus the ambient
  /// curve's value at the first sample (°C). The gyro starts soaked at the true ambient, which
  /// the curve knows only to its first value's standard error (its prior, AmbientFree); at 1 s
  /// samples the reference generator's curves started 0.4-0.8 mK off, which the block and
  /// anode kept for hours. Like per-run gains, its prior counts in the calibration's fit and in
  /// every refit, not in a candidate's score (KnobPriorCost: the knobs' alone).
  std::vector<double> start;
  /// Per run and source, a factor on the source's gain (DiagnoseOptions::per_run_source_gains;
  /// empty without them).
  std::vector<std::vector<double>> run_gain;
};

/// The nominal gyro with m's knobs and effects.
sim::GyroConfig Build(const sim::GyroConfig& nominal, const std::vector<BaseKnob>& knobs, const Model& m);

}  // namespace rlg::diagnosis
