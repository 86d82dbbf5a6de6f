#pragma once
/// A fitted compensation model (model/compensation_model.h) written out as C99 source that runs
/// the causal compensator on the gyro's own processor (`rlgtherm export --c`, docs/firmware.md):
/// two files, <prefix>.h and <prefix>.c, with the fitted coefficients as constants and this API
/// (prefix rlg_comp, double; with CPrecision::kFloat every `double` below is `float`):
///
///   typedef struct { ... } rlg_comp_state;      plain data, owned by the caller
///   void   rlg_comp_init(rlg_comp_state *s);    power-on: the next sample starts a run
///   double rlg_comp_update(rlg_comp_state *s, double t_s, const double *T_C, double bias_dph);
///
/// t_s in s (increasing), T_C the model's RLG_COMP_CHANNELS temperature channels in °C in the
/// order ModelCompensator::channels() takes them, bias and result in °/h.
///
/// Arithmetic. Double code does the C++ compensator's operations on the same doubles
/// (compensation/compensator.h for Eq. (2); model/linear_compensator.h, model/poly_model.h and
/// model/causal_operators.h for the polynomials), summing left to right where Eigen's vectorised
/// sums pair terms otherwise (a3 of Eq. (2), a polynomial's final sum): a few units in the last
/// place. Float code does the same in float but for the lag term, which it keeps as its deviation
/// E = L - T_prev (E_k = a E - ((1 - a) / x) (T - T_prev), the same recursion rearranged): L itself
/// near 50 °C in float is spaced 3.8e-6 °C, and its step (1 - a)(T - L) is rounded to that spacing
/// (lost below half of it: |T - L| < 8e-3 °C at tau = 2122 s, dt = 0.5 s). On the IMU log the
/// direct form in float errs by up to 2.9e-3 °/h, this one by 1.6e-4 °/h. Rate and lag terms and
/// rate factors call expm1 (expm1f) every sample, as the C++ does, so sample times may be
/// irregular; no other model needs libm.
///
/// Product terms: each factor as PolyRegressors::Next computes it (the signal, a rate factor's
/// through a low-pass of its own in the state; flagged beyond the range it spanned in the fit and
/// clamped to it unless the model extrapolates; then T_ref off a channel's value), multiplied
/// left to right. With rate factors, 1 - exp(-dt / tau_r) is evaluated once per time constant and
/// shared by the filters that have it (the library's RateFilters each evaluate the same value).
/// An extrapolating model (beyond_range extrapolate) clamps nothing, the flag is set all the same.
///
/// The generated files are ASCII, use no heap and no mutable global state, and compile without
/// a warning under `-std=c99 -Wall -Wextra -pedantic` (tests/export).

#include <string>
#include <vector>

#include "model/compensation_model.h"

namespace rlg::compensation {

enum class CPrecision { kDouble, kFloat };

/// "double" / "float", as the option and the files spell them.
const char* CPrecisionName(CPrecision p);

struct CExportOptions {
  CPrecision precision = CPrecision::kDouble;
  /// The files' stem and every name's prefix: <prefix>_state, <prefix>_init, <prefix>_update,
  /// and in upper case the macros <PREFIX>_CHANNELS, ... A C identifier of letters, digits and
  /// '_', starting with a letter, at most 31 characters (C99's guaranteed significant length
  /// of an external name), not ending in '_'.
  std::string prefix = "rlg_comp";
  /// What the coefficients were read from, named in the files' first comment ("" : not named).
  std::string source;

  bool IsValid(std::string* error) const;
};

/// The two files' names and text.
struct CCode {
  std::string header_name, header;  ///< <prefix>.h
  std::string source_name, source;  ///< <prefix>.c
};

/// The C code of `model`. InputError when the options are not valid (the message names the
/// option and what it expects).
CCode ExportC(const model::FittedModel& model, const CExportOptions& options);

/// ExportC written into directory `dir` whole or not at all (io::OutputDirectory: created with
/// its parents if missing; other files in it are left alone). Returns the paths written.
std::vector<std::string> WriteC(const model::FittedModel& model, const std::string& dir, const CExportOptions& options);

}  // namespace rlg::compensation
