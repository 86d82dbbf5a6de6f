#pragma once
/// The thermal least-squares fit of a diagnosis: the one place that uses Ceres.
///
/// For the free parameters x (network/free.h) of a model, over the runs `which`, minimises
///     1/2 sum_runs sum_s sum_blocks (e / sqrt(var_s))² + 1/2 sum_priors ((x - center) / sigma)²
/// with e the thermal residual (simulated - measured, fit-block means, °C) and var_s the
/// channel variance (°C², ChannelVariances), by Levenberg-Marquardt (dense QR) with
/// forward-difference Jacobians of the noise-free simulation (relative step
/// CalibrationOptions::relative_step, stop at CalibrationOptions::function_tolerance).
///
/// Parameter blocks: the shared parameters (knobs, effect parameters) and, per run, its own
/// nuisances (ambient, heater gains, start). A run's residuals depend on the shared block and
/// its own only, so each run is one residual block: a numeric Jacobian re-simulates one run
/// per parameter instead of every run. A failed simulation at a trial point (CVODE, or a
/// non-finite residual) is a failed evaluation, and Ceres shrinks its step.

#include <Eigen/Core>
#include <vector>

#include "diagnosis/network/free.h"
#include "diagnosis/network/model.h"
#include "diagnosis/network/problem.h"

namespace rlg::diagnosis {

/// What one least-squares pass reports (Ceres' Summary, the parts the stages use).
struct FitSummary {
  bool usable = true;  ///< Ceres' IsSolutionUsable; nothing to fit is usable
  double initial_cost = 0.0, final_cost = 0.0;
  int iterations = 0;
};

struct ThermalFit {
  /// The fitted model where the fit is usable; else the start (the simulation failed there).
  Model model;
  FitSummary summary;
  /// J^T J of the weighted residuals and prior rows at the optimum, columns in the order of
  /// the parameter blocks (the shared block, knobs first, leads); only when asked for and
  /// usable.
  Eigen::MatrixXd jtj;
};

/// The fit above of `free` from `start`, at most max_iterations iterations.
ThermalFit FitThermal(const Problem& p, const Model& start, const std::vector<Free>& free, const std::vector<int>& which,
                      const std::vector<double>& channel_var, int max_iterations, bool with_jtj = false);

}  // namespace rlg::diagnosis
