#pragma once
/// The sample times of a fit block, and block means of smooth quantities from their values at
/// the blocks' mean sample times.
///
/// For a block of samples t_1..t_n with mean m and variance var(t) = mean((t_k - m)²), the
/// mean of a smooth q over the block is, to fourth order,
///     mean(q) = q(m) + q''(m) var(t) / 2,
/// with q''(m) / 2 the second divided difference through this block's and its neighbours'
/// values at their mean times (the nearest three at a run's ends).

#include <Eigen/Core>
#include <utility>
#include <vector>

namespace rlg::diagnosis {

/// The sample times of one fit block: their mean and their variance about it (s, s²).
struct BlockTimes {
  double mean, variance;
};

/// The BlockTimes of samples [b.first, b.second) of t. Precondition: b is not empty.
BlockTimes TimesOf(const std::vector<double>& t, std::pair<size_t, size_t> b);

/// Block means of smooth quantities (rows of q, one column per block) from their values at
/// the blocks' mean sample times, by the formula above. Taking q(m) alone was wrong by
/// q'' var / 2 where an ambient corner starts a curvature: 0.22 mK on the cabinet after a
/// ramp's start (10 s blocks of 0.1 s or 1 s data), 1.7 times the noise of a 100 s mean of
/// 0.1 s data. One-sample blocks have no variance and stay as they are; fewer than three
/// blocks are left as they are.
void ToBlockMeans(const std::vector<BlockTimes>& blocks, Eigen::Ref<Eigen::MatrixXd> q);

}  // namespace rlg::diagnosis
