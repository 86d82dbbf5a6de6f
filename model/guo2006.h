#pragma once
/// The seed paper's compensation model, Eq. (2), for any sensor pair (Pi, Pj):
///
///   B = B0 + a1 dT + a2 dT² + a3 (Tj - Ti),   dT = Ti - Ti0
///   a_k = A_k0 + A_k1 Ti0 + A_k2 Ti0²,         k = 1, 2, 3
///
/// Ti0 is the first sample of Ti in a run (power-on) and B0 the mean bias over the first
/// `b0_window_s` seconds (120 s in the paper). Units: °/h and °C. Written as one linear model,
/// B - B0 = sum_{k,l} A_kl f_k Ti0^l, with regressors f = [dT, dT², Tj - Ti] (Guo2006Row):
/// batch fitting and the causal compensator call the same code.
///
/// Two fits are offered:
///  - joint:     all nine A_kl in one linear least squares over every sample of every run
///               (Householder QR on column-scaled regressors; default);
///  - two_stage: the paper's description: per run a_k by least squares, then for each k a
///               quadratic in Ti0 across runs.
/// Both report the condition number of the (column-scaled) problem and standard errors, and
/// refuse (NumericalError, exit 3) a problem whose coefficients the data cannot identify.

#include <Eigen/Dense>
#include <array>
#include <string>
#include <vector>

#include "sim/trace.h"

namespace rlg::model {

/// The three regressors of one sample: f = [dT, dT², Tj - Ti].
Eigen::Vector3d Guo2006Features(double Ti, double Tj, double Ti0);
/// The nine regressors of one sample: [f_k Ti0^l] for k = 1..3 (row-major over l = 0..2).
using Row9 = Eigen::Matrix<double, 9, 1>;
Row9 Guo2006Row(double Ti, double Tj, double Ti0);

struct Guo2006Coefficients {
  std::array<std::string, 2> pair{"T1", "T2"};
  double b0_window_s = 120.0;
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();         ///< A(k-1, l) = A_kl
  Eigen::Matrix3d A_stderr = Eigen::Matrix3d::Zero();  ///< standard errors (white-residual formula)
  std::array<double, 2> t10_range_C{0.0, 0.0};
  double condition_number = 0.0;
  double residual_rms_dph = 0.0;
  std::string method = "joint";
  std::vector<std::string> runs;

  /// a_k at a given Ti0.
  Eigen::Vector3d RunCoefficients(double Ti0) const;
  /// B - B0 predicted for one sample.
  double Predict(double Ti, double Tj, double Ti0) const;
};

struct FitOptions {
  std::array<std::string, 2> pair{"T1", "T2"};
  double b0_window_s = 120.0;  ///< B0 = mean bias over [t_first, t_first + window)
  enum class Method { kJoint, kTwoStage };
  Method method = Method::kJoint;
  /// A scaled condition number above this means the coefficients are not identifiable.
  double max_condition_number = 1e8;
};

/// Mean bias over the first `window_s` seconds of a run; InputError if the run is shorter.
double InitialBias(const sim::Run& run, double window_s);

/// Eq. (3)'s inner sum for one run: the sum over samples of (bias - B0 - model)². The fits
/// report their residual from it too.
double RunSse(const Guo2006Coefficients& c, const sim::Run& run);

/// Fits Eq. (2) to every run of `runs`. InputError for a missing channel or a run shorter than
/// the B0 window; NumericalError when the data cannot identify the coefficients (the message
/// names them and says what data would).
Guo2006Coefficients FitGuo2006(const std::vector<const sim::Run*>& runs, const FitOptions& options);

}  // namespace rlg::model
