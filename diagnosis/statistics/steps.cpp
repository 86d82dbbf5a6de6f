#include "diagnosis/statistics/steps.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

namespace rlg::diagnosis {

std::optional<DetectedStep> LargestStep(const Eigen::Ref<const Eigen::VectorXd>& e, const std::vector<double>& t_s,
                                        const std::string& run, Eigen::Index min_blocks) {
  const Eigen::Index n = e.size();
  if (n < std::max<Eigen::Index>(min_blocks, 2) || static_cast<Eigen::Index>(t_s.size()) != n) return std::nullopt;
  // sigma and rho of the residual as it is, step included. (Taken with the step removed, each
  // side about its own mean, null datasets of the diagnosis suite reached 22 on 900 blocks:
  // bias instability wanders on time scales the lag-1 factor does not see.)
  const Eigen::ArrayXd c = e.array() - e.mean();
  const double c0 = c.square().sum();
  if (!(c0 > 0.0)) return std::nullopt;
  const double rho = std::clamp((c.head(n - 1) * c.tail(n - 1)).sum() / c0, 0.0, 0.95);
  const double sigma = std::sqrt(c0 / static_cast<double>(n - 1) * (1.0 + rho) / (1.0 - rho));
  double left = 0.0, best = 0.0, jump = 0.0;
  Eigen::Index at = 0;
  const double total = e.sum();
  for (Eigen::Index k = 1; k < n; ++k) {
    left += e[k - 1];
    const double nl = static_cast<double>(k), nr = static_cast<double>(n - k);
    const double d = (total - left) / nr - left / nl;
    const double z = std::abs(d) * std::sqrt(nl * nr / static_cast<double>(n)) / sigma;
    if (z > best) best = z, at = k, jump = d;
  }
  return DetectedStep{run, t_s[static_cast<size_t>(at)], jump, best, kStepThreshold};
}

std::string StepNote(const DetectedStep& s) {
  return fmt::format("run '{}': largest step of the bias residual {:+.4f} °/h near t = {:.0f} s (statistic {:.1f})", s.run,
                     s.size, s.t_s, s.statistic);
}

}  // namespace rlg::diagnosis
