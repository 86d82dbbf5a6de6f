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
/// Two fits are offered; both give every run its own bias level (a nuisance offset, see below):
///  - joint:     all nine A_kl in one linear least squares over every sample of every run
///               (Householder QR on column-scaled regressors; default);
///  - two_stage: the paper's description: per run a_k by least squares, then for each k a
///               quadratic in Ti0 across runs.
/// Both report the condition number of the (column-scaled) problem and standard errors, and
/// refuse (NumericalError, exit 3) a problem whose coefficients the data cannot identify.
///
/// Why a per-run offset. B0 is a 120 s mean: its noise error (0.02 °/h / sqrt(12) at 10 s
/// samples) is common to every sample of the run, and the temperatures already move while it
/// is taken. Fitting y = bias - B0 without an offset treats that error as independent per
/// sample: standard errors several times too small and A_kl biased by what the model does in
/// the window. With an offset per run the fit uses only how the bias moves within each run,
/// which is exactly the least squares of bias = c_r + sum A_kl f_k Ti0^l with c_r unknown: the
/// best linear unbiased estimate under white noise (GLS with the B0 error's covariance
/// sigma^2 I + sigma_B0^2 11^T tends to it as sigma_B0 grows, and would need sigma_B0). Measured
/// (tests/model/test_guo2006_coverage.cpp, 1,500 datasets of 9 warm-ups): no bias, and the
/// joint fit's spread of the A_kl 0.3-0.8 times what it was without the offset (A22, A32: 0.3).
/// `compensate` still subtracts the run's B0 as the paper does.
///
/// Standard errors (stderr_method):
///  - "run_scatter" (4 or more runs): from how the runs scatter about the fit, so that bias
///    instability and other slow noise, which the residuals within a 2 h run cannot show, count.
///    Two-stage: the scatter of the per-run a_k about each quadratic, m - 3 degrees of freedom
///    for m runs. Joint: each run's three projected errors (z_r - R3_r a_r in the compressed
///    problem) get one 3x3 covariance common to all runs, estimated without bias from the
///    compressed residuals and propagated through the fit; Satterthwaite degrees of freedom
///    per coefficient (Bell-McCaffrey, at the working model of white noise). Under white noise
///    the projected errors are sigma^2 I in every run, so the model holds; with bias
///    instability it is an approximation. Measured coverage of the 95 % intervals, 9 runs:
///    94.6-95.5 % (white), 94.5-95.7 % (white + bias instability); with 4-6 runs they are
///    conservative (96-99 % on average). Also tried: the white-noise formula covered 65-84 %
///    with bias instability; run-clustered CR2 errors 94-99 % with intervals 5-50 % wider; one
///    isotropic covariance 90-99 %.
///  - "within_run_white" (3 runs: the fit is exact in Ti0 and leaves no scatter): from the
///    within-run residuals, assuming white noise; bias instability is not counted.
/// ConfidenceHalfWidth turns them into intervals with Student's t at stderr_dof.

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
  Eigen::Matrix3d A_stderr = Eigen::Matrix3d::Zero();  ///< standard errors (see stderr_method)
  Eigen::Matrix3d stderr_dof = Eigen::Matrix3d::Zero();  ///< degrees of freedom of each (Student's t)
  std::string stderr_method = "run_scatter";             ///< or "within_run_white" (see above)
  std::array<double, 2> t10_range_C{0.0, 0.0};
  double condition_number = 0.0;
  double residual_rms_dph = 0.0;
  std::string method = "joint";
  std::vector<std::string> runs;

  /// a_k at a given Ti0.
  Eigen::Vector3d RunCoefficients(double Ti0) const;
  /// B - B0 predicted for one sample.
  double Predict(double Ti, double Tj, double Ti0) const;
  /// Half-widths of two-sided confidence intervals at `level` (0 < level < 1):
  /// t_{(1 + level) / 2, stderr_dof(k,l)} A_stderr(k,l). Needs stderr_dof > 0 (a fit's, not a
  /// file's coefficients).
  Eigen::Matrix3d ConfidenceHalfWidth(double level = 0.95) const;
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

/// Fits Eq. (2) to every run of `runs`. InputError for a missing channel, a run shorter than
/// the B0 window or with fewer than 4 samples (its offset and three temperature terms);
/// NumericalError when the data cannot identify the coefficients (fewer than 3 distinct Ti0,
/// temperatures that do not move: the message names the coefficients and says what data would).
Guo2006Coefficients FitGuo2006(const std::vector<const sim::Run*>& runs, const FitOptions& options);

}  // namespace rlg::model
