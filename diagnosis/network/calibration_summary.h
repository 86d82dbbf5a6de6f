#pragma once
/// What stage 2 of a diagnosis (network/calibrate.h) reports: each knob's nominal and calibrated value,
/// its shift from nominal in prior sds, its posterior sd, each run's fitted start, the fit's
/// cost and iterations, and the knobs' posterior covariance (log units); with the prior
/// conflicts read from them: a knob beyond kPriorConflictSigma prior sds, or the knobs jointly
/// (sum of squared shifts against chi² with one degree of freedom per knob, below
/// kJointConflictP).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "diagnosis/statistics/identifiability.h"

namespace rlg::diagnosis {

/// A knob of the calibration: nominal and calibrated values in physical units (J/K, W/K, m²,
/// or a gain of 1 nominal) and the shift ln(calibrated / nominal) in prior sds.
struct KnobCalibration {
  std::string name;  ///< "C:node", "G:a-b", "eA:a-b", "gain:source"
  double nominal = 0.0;
  double calibrated = 0.0;
  double shift_sigma = 0.0;
  double posterior_sd = 0.0;  ///< log units
  KnobLabel label{};          ///< the name again, with what the knob is
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
  /// is kept (Calibrate, network/calibrate.h).
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
