#pragma once
/// The free parameters of a thermal least-squares fit, and how they map to a Model.
///
/// A free parameter is a baseline knob, an effect parameter, or a run's nuisance (its ambient,
/// a source's gain, its start). Each is fitted as x = ln v when `log`, else as v, with v in
/// internal units: knobs, effect parameters and gains in their physical units, a run's ambient
/// and its start as absolute temperatures in kelvin:
///     ambient: v = Model::ambient[r] + kKelvin
///     start:   v = CurveStart(r) + Model::start[r] + kKelvin
/// A prior (prior_sigma > 0) adds ((x - prior_center) / prior_sigma)² to the fit's chi².

#include <string>
#include <vector>

#include "diagnosis/network/model.h"
#include "diagnosis/network/problem.h"

namespace rlg::diagnosis {

struct Free {
  enum Kind { kBase, kEffect, kAmbient, kRunGain, kStart } kind;
  int index;          ///< knob, effect (Model::effects), or run
  std::string param;  ///< effect parameter name; for a run's gain, the source's index
  bool log;
  double prior_center = 0.0;  ///< internal units (of x)
  double prior_sigma = 0.0;   ///< 0 = none
};

inline constexpr double kKelvin = 273.15;  ///< a run's ambient and start are fitted in K

/// Run r's logged ambient curve at its first sample (°C). A start is fitted as this plus
/// Model::start, an absolute temperature in kelvin, as an unlogged ambient is: the numeric
/// Jacobian's relative step (1e-6) is then 3e-4 K at any chamber temperature, whereas 1e-6 of
/// a 0.2 mK offset, 2e-10 °C, is below CVODE's tolerance and its derivative noise (a refit
/// through CVODE then takes minutes, not seconds), and 1e-6 of a 0 °C chamber in °C is Ceres'
/// floor of 1.5e-8.
double CurveStart(const Problem& p, int r);

/// Sets parameter f of m to the fitted value x.
void SetOne(const Problem& p, Model& m, const Free& f, double x);
/// SetOne of every free[i] to x[i].
void SetFree(const Problem& p, Model& m, const std::vector<Free>& free, const double* x);
/// The fitted values x of `free` in m.
std::vector<double> GetFree(const Problem& p, const Model& m, const std::vector<Free>& free);

/// Every baseline knob, in log units with a prior of the gyro file's relative uncertainty
/// about its nominal, then AmbientFree(which_ambient).
std::vector<Free> BaselineFree(const Problem& p, const std::vector<int>& which_ambient);

/// Per-run nuisances of the runs `which` (a run that shares another's nuisances has none of
/// its own): the ambient where it was not logged; the start (Model::start) where it is logged
/// with noise, with a prior of the standard error of the curve's first value
/// (Problem::start_sd); and with per-run source gains, each data-driven source's gain, in log
/// units, relative to the global one, with a prior of the gyro's relative uncertainty about 1.
std::vector<Free> AmbientFree(const Problem& p, const std::vector<int>& which);

}  // namespace rlg::diagnosis
