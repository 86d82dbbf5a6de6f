#include "diagnosis/data/block_times.h"

#include <algorithm>

namespace rlg::diagnosis {

BlockTimes TimesOf(const std::vector<double>& t, std::pair<size_t, size_t> b) {
  BlockTimes out{0.0, 0.0};
  for (size_t i = b.first; i < b.second; ++i) out.mean += t[i];
  out.mean /= static_cast<double>(b.second - b.first);
  for (size_t i = b.first; i < b.second; ++i) out.variance += (t[i] - out.mean) * (t[i] - out.mean);
  out.variance /= static_cast<double>(b.second - b.first);
  return out;
}

void ToBlockMeans(const std::vector<BlockTimes>& blocks, Eigen::Ref<Eigen::MatrixXd> q) {
  const auto n = static_cast<Eigen::Index>(blocks.size());
  if (n < 3) return;
  // One-sample blocks (10 s blocks of 10 s data) have nothing to add: no copy of q.
  if (std::none_of(blocks.begin(), blocks.end(), [](const BlockTimes& b) { return b.variance > 0.0; })) return;
  const Eigen::MatrixXd at_mean = q;
  for (Eigen::Index k = 0; k < n; ++k) {
    const double var = blocks[static_cast<size_t>(k)].variance;
    if (var <= 0.0) continue;
    const Eigen::Index c = std::clamp<Eigen::Index>(k, 1, n - 2);
    const double t0 = blocks[static_cast<size_t>(c - 1)].mean, t1 = blocks[static_cast<size_t>(c)].mean,
                 t2 = blocks[static_cast<size_t>(c + 1)].mean;
    q.col(k) += var * (((at_mean.col(c + 1) - at_mean.col(c)) / (t2 - t1) - (at_mean.col(c) - at_mean.col(c - 1)) / (t1 - t0)) /
                       (t2 - t0));
  }
}

}  // namespace rlg::diagnosis
