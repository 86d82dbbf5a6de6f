#pragma once
/// Identifiability of the calibrated knobs (part of stage 2, calibration): which combinations
/// of knobs the data determine and which the prior holds.
///
/// With S the knobs' posterior covariance (log units) and s the prior sd of every knob (the
/// gyro file's relative uncertainty), the eigen-directions v_j of S / s² with eigenvalues λ_j
/// are combinations sum_i v_ji ln(knob_i) whose posterior sd is sqrt(λ_j) times the prior's.
/// Near 1 the data say nothing about the combination and the prior holds it; a direction is
/// counted as determined below kDeterminedSdRatio. Raw pairwise correlations would mislead:
/// one undetermined direction makes every pair look ±1 correlated, so correlations are
/// reported given the common scale (CorrelationsGivenScale).

#include <Eigen/Core>
#include <string>
#include <utility>
#include <vector>

namespace rlg::diagnosis {

/// What a calibrated knob scales: the reasons below read it, never the knob's name.
enum class KnobKind {
  kHeatCapacity,  ///< a node's C (J/K)
  kConductance,   ///< a link's G (W/K)
  kRadiation,     ///< a radiating pair's emissivity x area (m²)
  kGain,          ///< a heat source's gain
};

/// A knob as the analysis reads it.
struct KnobLabel {
  std::string name;  ///< as reported: "C:node", "G:a-b", "eA:a-b", "gain:source"
  KnobKind kind = KnobKind::kHeatCapacity;
  bool to_ambient = false;  ///< a link or radiating pair with ambient
};

/// One combination of knobs the data leave (mostly) to the prior.
struct IdentifiabilityDirection {
  /// Posterior over prior sd of the combination, sqrt(λ) >= kDeterminedSdRatio.
  double sd_ratio = 0.0;
  /// (knob, loading) of the unit eigenvector, every knob, largest |loading| first; signed so
  /// that the loadings sum to >= 0.
  std::vector<std::pair<std::string, double>> loadings;
  /// Why no temperature record fixes it, where a physical reason is known; else empty.
  std::string reason;
};

struct Identifiability {
  int knobs = 0;        ///< combinations in all (= knobs)
  int determined = 0;   ///< combinations with sd_ratio below kDeterminedSdRatio
  double prior_sd = 0.0;  ///< log units
  std::vector<IdentifiabilityDirection> undetermined;  ///< largest sd_ratio first
};

/// Posterior sd below half the prior's: the data reduce the uncertainty of the combination at
/// least 2x; above, the calibrated value is mostly the nominal one.
inline constexpr double kDeterminedSdRatio = 0.5;
/// Loadings listed in the report's text: those of magnitude at least this, at most six.
inline constexpr double kListedLoading = 0.15;

/// The eigen-analysis above of `cov` (knobs x knobs, log units) for `knobs`, in its order.
Identifiability AnalyseIdentifiability(const Eigen::MatrixXd& cov, const std::vector<KnobLabel>& knobs,
                                       double prior_sd);

/// The report's lines: the count of determined combinations first, then one per undetermined
/// direction; none without knobs.
std::vector<std::string> IdentifiabilityNotes(const Identifiability& id);

/// Correlations of the knobs (log units) given their common scale, which no temperature record
/// fixes: that one loose direction alone would make every pair +1. With u the scale direction,
/// the covariance given u^T x is S - S u (u^T S u)^-1 u^T S. Within [-1, 1]; NaN for a knob that
/// is (to round-off) the scale itself. Needs two or more knobs.
Eigen::MatrixXd CorrelationsGivenScale(const Eigen::MatrixXd& cov);

}  // namespace rlg::diagnosis
