#pragma once
/// The null bootstrap of a diagnosis without a thermal network: the score a candidate must
/// reach, from a parametric bootstrap of the baseline's residuals.
///
/// There is no gyro file whose noise could make null data (network/bias_null.h), so the noise is the
/// data's own: the baseline regression (the model's columns, fitted on the fitted units) leaves
/// fit-block residuals that are autocorrelated (bias instability, slow misfit), and treating
/// them as independent samples would let a slowly varying candidate pass on noise alone. They
/// are modelled by an AR(p) process (statistics/ar_noise.h: Yule-Walker, order up to 10 by AIC, segments
/// cut where a unit's counted blocks are not consecutive), and each replicate is
///
///     y*_r = X_r beta + e*_r,    e*_r drawn from the AR model over every block of run r
///
/// (DrawReplicates, replicate b, run r from sim::Rng(b + 1, r)). Its score is the best candidate's
/// (ScoreMeasured, every profile searched again) among those that also pass the held-out test
/// (min_heldout_ratio), -infinity where none does; the threshold is max(min_score, the largest
/// replicate score): with 40 replicates a null dataset beats it about 2.5 % of the time.
/// Whatever the baseline misses is in its residuals and so in the AR model too: the threshold
/// errs high (a missed term makes the noise look slower and larger), never low.

#include <cstdint>
#include <string>
#include <vector>

#include "diagnosis/statistics/ar_noise.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/without_network/candidates.h"
#include "diagnosis/without_network/problem.h"

namespace rlg::diagnosis {

struct MeasuredNull {
  NullBootstrap bootstrap;
  ArModel noise;  ///< the residuals' model (fit-block means, °/h)
};

/// The AR model of the in-sample fit-block residuals of the regression of the data's bias on
/// `columns` (the fitted units, cut where their counted blocks are not consecutive).
ArModel ResidualNoise(const MeasuredProblem& p, const std::vector<RunColumns>& columns);

/// `count` replicates of the data's bias: the regression on `columns` fitted on the fitted units,
/// at every block of every run, plus `noise` drawn per run (replicate b, run r from
/// sim::Rng(b + 1, r, substream)).
std::vector<RunColumns> DrawReplicates(const MeasuredProblem& p, const std::vector<RunColumns>& columns,
                                       const ArModel& noise, int count, uint64_t substream);

/// options.null_replicates replicates of the regression of the data's bias on `model_columns`,
/// with the noise of its residuals, scored (substream 0).
MeasuredNull NullFromResiduals(const MeasuredProblem& p, const std::vector<RunColumns>& model_columns,
                               const std::vector<MeasuredCandidate>& candidates);

/// What the report says of it: the noise model, the threshold, how many replicates let some
/// candidate pass the held-out test.
std::string MeasuredNullNote(const MeasuredProblem& p, const MeasuredNull& null);

}  // namespace rlg::diagnosis
