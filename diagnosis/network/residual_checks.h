#pragma once
/// Stage 3 of a diagnosis: the calibrated baseline's residual checks, before any search.
///
///  - whiteness: the Ljung-Box p-value over 10 lags (statistics/score.h: LjungBoxP) of each temperature
///    channel's fit-block residuals pooled over every run and, with bias data, of the held-out
///    bias residuals pooled over the scored runs;
///  - steps: per scored run, the largest step of the held-out bias residual (statistics/steps.h:
///    LargestStep), reported where its statistic exceeds its threshold.

#include <map>
#include <string>
#include <vector>

#include "diagnosis/network/model.h"
#include "diagnosis/network/problem.h"
#include "diagnosis/statistics/steps.h"

namespace rlg::diagnosis {

struct ResidualChecks {
  std::map<std::string, double> ljung_box_p;  ///< channel or "bias_dph" -> p-value
  std::vector<DetectedStep> detected_steps;   ///< the steps above their threshold
  std::vector<std::string> notes;             ///< StepNote of each
};

ResidualChecks CheckResiduals(const Problem& p, const Model& m);

}  // namespace rlg::diagnosis
