#pragma once
/// Stage 5 of a diagnosis without a thermal network: every candidate (without_network/candidates.h)
/// scored as the bias search scores its own (network/bias_search.h, statistics/score.h). Its column joins the
/// regression of the model's columns (the baseline polynomial's and those accepted so far), each
/// unit with its own offset (statistics/bias_fit.h), and
///  - its score is the information gain of the in-sample fit, fit-block residuals of the fitted
///    units (InformationGain: n_eff from their lag-1 autocorrelation; k = 1 + its profiled
///    parameters, so the search over tau or w is priced);
///  - its held-out RMS ratio compares the score-block means of the scored units' held-out
///    residuals (HeldOutBias: the held-out units, or leave-one-run-out) without and with it.
/// A profiled parameter is the minimiser of the in-sample sum of squares over its bounds
/// (model/profile_search.h MinimizeOnLogScale: 16 log-spaced points, then golden section to
/// 0.1 %), every linear coefficient solved at each trial; the held-out units never enter it.

#include <Eigen/Core>
#include <set>
#include <string>
#include <vector>

#include "diagnosis/candidate.h"
#include "diagnosis/without_network/candidates.h"
#include "diagnosis/without_network/problem.h"

namespace rlg::diagnosis {

/// A scored candidate and its column at the fitted parameter.
struct MeasuredScored {
  Candidate candidate;  ///< kind kBias
  RunColumns column;
};

/// Every candidate not in `taken`, scored against the regression of `model_columns` on `y` (per
/// run, per block: the data's bias, or a null replicate's), in the candidates' order.
std::vector<MeasuredScored> ScoreMeasured(const MeasuredProblem& p, const std::vector<RunColumns>& model_columns,
                                          const std::vector<MeasuredCandidate>& candidates,
                                          const std::set<CauseTarget>& taken, const RunColumns& y);

/// The regression of `y` on `model_columns` (and `extra`, when given), fitted (FitMeasured).
MeasuredFit FitColumns(const MeasuredProblem& p, const std::vector<RunColumns>& model_columns, const RunColumns& y,
                       const RunColumns* extra = nullptr);

}  // namespace rlg::diagnosis
