#pragma once
/// Step detection in a residual series (part of stage 3 of the diagnosis, the residual checks):
/// the single split with the largest two-sample statistic
///     z(k) = |mean(e[k..n)) - mean(e[0..k))| sqrt(k (n - k) / n) / sigma,
/// sigma the residual's sd widened by its AR(1) factor sqrt((1 + rho) / (1 - rho)) (rho the
/// lag-1 autocorrelation clamped to [0, 0.95]): bias instability wanders, and a wandering
/// residual would otherwise show a "step" anywhere. A split above kStepThreshold is reported.
/// The step itself inflates sigma and rho, so the statistic of a clean step saturates as the
/// step grows (near sqrt(n) / 6.2): on fewer than ~500 blocks no step reaches the threshold.
/// Estimating them without the step instead made null data (bias instability) reach 22 on 900
/// blocks; a threshold from the null bootstrap's replicates would fix both (not done yet).

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

namespace rlg::diagnosis {

/// A step found in one run's held-out bias residual.
struct DetectedStep {
  std::string run;         ///< run label
  double t_s = 0.0;        ///< time of the first block after the step (s)
  double size = 0.0;       ///< mean after minus mean before (unit of the residual, °/h for the bias)
  double statistic = 0.0;  ///< z above
  double threshold = 0.0;  ///< what z had to exceed
};

/// z above which a step is reported: on null datasets of the diagnosis suite (bias
/// instability only) the largest z reached 8.2.
inline constexpr double kStepThreshold = 9.0;

/// The largest split of `e` (one value per block, block mid-times `t_s`, same length), with
/// `run` as its label; none for fewer than `min_blocks` values or a constant series. Whether
/// it counts is statistic > threshold (kStepThreshold).
std::optional<DetectedStep> LargestStep(const Eigen::Ref<const Eigen::VectorXd>& e, const std::vector<double>& t_s,
                                        const std::string& run, Eigen::Index min_blocks = 20);

/// The report's line for a step.
std::string StepNote(const DetectedStep& step);

}  // namespace rlg::diagnosis
