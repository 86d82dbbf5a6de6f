#pragma once
/// Stage 3 of the diagnosis: calibration of the nominal thermal network to the data (docs/diagnosis.md):
/// the baseline decides everything that follows.
///
/// The knobs x (log heat capacities, log conductances, log radiating areas, log source gains)
/// and the per-run nuisances (an unlogged ambient, per-run heater gains, the start where the
/// ambient is logged with noise) minimise
///     1/2 sum_runs sum_channels sum_blocks ((T_sim - T_meas) / sigma_channel)²
///       + 1/2 sum_knobs ((x_i - ln nominal_i) / s)²
///       + 1/2 sum_runs (start_r / sd_r)² + 1/2 sum_gains ((ln g - 0) / s)²
/// (sd_r the standard error of run r's ambient curve at its first sample).
/// by Levenberg-Marquardt (Ceres, dense QR, forward-difference Jacobians of the noise-free
/// simulation), s the gyro file's relative uncertainty. sigma_channel comes from a first pass
/// with unit weights (the residual RMS of each channel, floored at 0.5 mK); the fit is then
/// repeated with it, and the held-out runs' nuisances are fitted with the knobs fixed. The
/// knobs' posterior covariance is (J^T J)^+ of the weighted residuals and prior rows at the
/// optimum.

#include <Eigen/Core>
#include <string>
#include <vector>

namespace rlg::diagnosis {

struct CalibrationOptions {
  /// Levenberg-Marquardt iterations of each of the two passes over the fit runs.
  int max_iterations = 50;
  /// Iterations of the held-out runs' nuisance fit (the knobs fixed; one or two unknowns per
  /// run, which converge in a few).
  int nuisance_max_iterations = 20;
  /// Ceres' relative cost decrease at which a pass stops.
  double function_tolerance = 1e-8;
  /// Relative step of the forward differences. With CVODE's tolerances matched to the data
  /// (SolverForData) the differences stay clean at 1e-6; a 1e-4 step made CVODE change its
  /// step sequence between the two evaluations, which turned radiation's derivative into noise.
  double relative_step = 1e-6;

  /// False with a reason in *error (may be null) for iterations below 1, a tolerance outside
  /// (0, 1) or a step outside (0, 0.1].
  bool IsValid(std::string* error) const;
};

/// A knob of the calibration: nominal and calibrated values in physical units (J/K, W/K, m²,
/// or a gain of 1 nominal) and the shift ln(calibrated / nominal) in prior sds.
struct KnobCalibration {
  std::string name;  ///< "C:node", "G:a-b", "eA:a-b", "gain:source"
  double nominal = 0.0;
  double calibrated = 0.0;
  double shift_sigma = 0.0;
  double posterior_sd = 0.0;  ///< log units
};

/// A run's start where its ambient is logged with noise: the gyro powers on soaked at the true
/// ambient, which the curve through the log knows to its first value's standard error, so the
/// start is a nuisance of the calibration (Model::start), reported as the offset of every state
/// from the curve's first value.
struct RunStart {
  std::string run;
  double offset_C = 0.0;    ///< fitted
  double prior_sd_C = 0.0;  ///< the standard error of the curve's first value
};

/// A knob moved by more than this many prior sds is a prior conflict: evidence that the
/// network lacks structure the calibration bent the knobs to imitate (docs/diagnosis.md).
inline constexpr double kPriorConflictSigma = 3.0;
/// The knobs' shifts are jointly in conflict with the prior below this chi² p-value: about the
/// two-sided probability of one knob beyond 3.3 sd.
inline constexpr double kJointConflictP = 1e-3;

struct CalibrationSummary {
  bool usable = false;        ///< Ceres' IsSolutionUsable of the final pass
  double initial_cost = 0.0;  ///< of the weighted second pass, before it (1/2 chi², prior included)
  double final_cost = 0.0;    ///< of the weighted second pass, after it
  int iterations = 0;         ///< of all three passes (of the start kept)
  /// The common factor on every heat capacity the kept fit started from: 1 from the nominal.
  /// A fit from the nominal that ends in a prior conflict and misses the data by well over
  /// their noise (a channel's residual variance above twice its white noise's) is repeated
  /// from the factor that fits the data best (a nominal with every capacity 30 % high, 4.4
  /// prior sds, ended twice in 30 in a minimum with the cathode's capacity +13 sd and its
  /// housing link +25 sd, 5x the noise on the block), and the one with the higher likelihood
  /// is kept (Engine::Calibrate).
  double start_capacity_scale = 1.0;
  double prior_sd = 0.0;      ///< every knob's prior sd, log units
  std::vector<KnobCalibration> knobs;
  std::vector<RunStart> starts;  ///< runs whose ambient is logged with noise (fitted ones)
  /// Posterior covariance of the knobs (log units), in the order of `knobs`.
  Eigen::MatrixXd covariance;

  /// Names of the knobs beyond kPriorConflictSigma, in the order of `knobs`.
  std::vector<std::string> PriorConflicts() const;
  /// The knobs' shifts taken together: sum of shift_sigma², and the probability of at least
  /// that much under the prior, a chi² of one degree per knob. A calibration's shifts are
  /// posterior means, pulled toward nominal, so under a right nominal their sum is at most that
  /// chi² in distribution and the p-value errs on the side of no conflict. Several knobs each
  /// short of kPriorConflictSigma can together be far beyond it: a nominal with every heat
  /// capacity 30 % high moved five knobs 2.4-2.9 sd, a sum near 56 over 13 knobs (p ~ 1e-6).
  double JointShiftChi2() const;
  double JointShiftP() const;
  /// JointShiftP() below kJointConflictP.
  bool JointConflict() const;
  /// Multi-line human summary, one knob per line (Ceres' Summary::FullReport in spirit).
  std::string FullReport() const;
};

}  // namespace rlg::diagnosis
