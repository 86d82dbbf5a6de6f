#pragma once
/// The held-out RMS of a model: per temperature channel, sqrt(ScoreSsr / n) over the scored
/// runs' score blocks (°C), and with bias data the RMS of the held-out bias residuals' score
/// blocks of its baseline regression (°/h).

#include "diagnosis/diagnose.h"
#include "diagnosis/network/model.h"
#include "diagnosis/network/problem.h"

namespace rlg::diagnosis {

Metrics Measure(const Problem& p, const Model& m);

}  // namespace rlg::diagnosis
