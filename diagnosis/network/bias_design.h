#pragma once
/// The bias regression of a model on a problem (statistics/bias_fit.h solves it): per run, the baseline
/// bias physics and any extra columns on fit blocks, evaluated on the model's predicted node
/// temperatures, against the fit-block means of the data's bias (°/h).
///
/// Baseline columns (sim::BaselineRegressors): dT, dT² and, per Langmuir gradient G, G and
/// G dT, with the gyro file's values as a prior of 100 % sd each (BaselinePrior). An extra
/// column is a function (prediction, fit block, run) -> regressor value, e.g. a bias effect's
/// term at unit coefficient.

#include <Eigen/Core>
#include <functional>
#include <vector>

#include "diagnosis/statistics/bias_fit.h"
#include "diagnosis/network/model.h"
#include "diagnosis/network/prediction.h"
#include "diagnosis/network/problem.h"
#include "diagnosis/statistics/score.h"

namespace rlg::diagnosis {

/// An extra column of the bias regression: its value on fit block k of run r of a prediction.
using Extra = std::function<double(const Prediction&, size_t, int)>;

/// The bias regression of model m (pred: its prediction on every run): per run, the baseline
/// and `extra` regressors on fit blocks and, as y, the fit-block means of the data's bias or,
/// given `bias_data` (per run, one value per counted fit block, °/h), those instead.
BiasDesign Design(const Problem& p, const Model& m, const std::vector<Prediction>& pred, const std::vector<Extra>& extra,
                  const std::vector<Eigen::VectorXd>* bias_data = nullptr);

/// Held-out bias residuals per run (HeldOutBias of statistics/bias_fit.h over the problem's split).
std::vector<Eigen::VectorXd> HeldOutBias(const Problem& p, const BiasDesign& d);

/// Score-block means of the scored runs' residuals, summarised for scoring.
ResidualFit ScoreBias(const Problem& p, const std::vector<Eigen::VectorXd>& res);

}  // namespace rlg::diagnosis
