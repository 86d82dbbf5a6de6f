#pragma once
/// What a model leaves of the data on every run of a problem: its prediction, the thermal
/// residuals (simulated - measured, °C, thermal_residuals.h) and, when the data have a bias, the
/// held-out bias residuals of its bias regression (°/h, bias_design.h). The residual checks, the
/// metrics and the report's traces start from it.

#include <Eigen/Core>
#include <vector>

#include "diagnosis/network/bias_design.h"
#include "diagnosis/network/model.h"
#include "diagnosis/network/prediction.h"
#include "diagnosis/network/problem.h"
#include "diagnosis/network/thermal_residuals.h"

namespace rlg::diagnosis {

struct ModelResiduals {
  std::vector<Prediction> prediction;       ///< per run of Problem::All
  ThermalResidualSet thermal;               ///< per run, sensor and counted fit block (°C)
  std::vector<Eigen::VectorXd> bias;        ///< held-out, per run (°/h); empty without bias data
};

/// The residuals of model m on every run; `extra`: the bias regression's extra columns.
ModelResiduals ResidualsOf(const Problem& p, const Model& m, const std::vector<Extra>& extra = {});

}  // namespace rlg::diagnosis
