#pragma once
/// Stage 7 of a diagnosis, its inputs: per run, the residuals of the calibrated baseline and of
/// the extended model at the fit-block resolution (the report's ResidualTrace), and per
/// temperature channel and run what statistics/unexplained.h weighs (the extended model's residual, its
/// noise and its covariates).

#include <vector>

#include "diagnosis/network/bias_design.h"
#include "diagnosis/diagnose.h"
#include "diagnosis/network/model.h"
#include "diagnosis/network/problem.h"
#include "diagnosis/statistics/unexplained.h"

namespace rlg::diagnosis {

struct Traces {
  std::vector<ResidualTrace> residuals;          ///< one per run
  std::vector<ChannelResidual> channel_residuals;  ///< per run, per temperature channel it has
};

/// The traces of `baseline` (no extra bias column) and `extended` (with `extended_columns`).
Traces MakeTraces(const Problem& p, const Model& baseline, const Model& extended, const std::vector<Extra>& extended_columns);

}  // namespace rlg::diagnosis
