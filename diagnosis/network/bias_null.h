#pragma once
/// The bias null bootstrap (docs/diagnosis.md): the score a bias candidate must reach.
///
/// Each replicate is bias data made of a model's fitted bias (its baseline regression, FitBias
/// on the fit runs) plus the gyro file's own noise (ARW, bias instability, quantization: the
/// simulator's GyroNoise, replicate b of run r seeded (b + 1, r)), block-averaged like the
/// data. Its score is the best bias candidate's (SearchBias, prewhitened like the data's) that also
/// passes the held-out test (a held-out gain above min_heldout_gain), -infinity where none does:
/// what noise alone reaches after a search of the whole catalog. The threshold is
/// max(min_score, the largest replicate score).

#include <string>
#include <vector>

#include "diagnosis/diagnose.h"
#include "diagnosis/network/model.h"
#include "diagnosis/network/prediction.h"
#include "diagnosis/network/problem.h"

namespace rlg::diagnosis {

/// options.null_replicates replicates of model m (pred: its prediction on every run).
NullBootstrap NullBiasThreshold(const Problem& p, const Model& m, const std::vector<Prediction>& pred);

/// What the report says of it: the threshold, the replicates, how many let some candidate pass
/// the held-out test.
std::string NullBootstrapNote(const Problem& p, const NullBootstrap& null);

}  // namespace rlg::diagnosis
