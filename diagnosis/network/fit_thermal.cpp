#include "diagnosis/network/fit_thermal.h"

#include <ceres/ceres.h>
#include <ceres/normal_prior.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <map>

#include "diagnosis/network/prediction.h"
#include "diagnosis/network/thermal_residuals.h"

namespace rlg::diagnosis {

namespace {

/// The fit's parameter blocks: indices into `free` and their values.
struct ParameterBlocks {
  std::vector<size_t> shared;                  ///< knobs, effect parameters
  std::map<int, std::vector<size_t>> own;      ///< run -> its nuisances
  std::vector<double> xs;                      ///< the shared block's values
  std::map<int, std::vector<double>> xr;       ///< run -> its block's values
};

ParameterBlocks SplitIntoBlocks(const Problem& p, const Model& m, const std::vector<Free>& free) {
  ParameterBlocks b;
  for (size_t i = 0; i < free.size(); ++i) {
    const bool per_run = free[i].kind == Free::kAmbient || free[i].kind == Free::kRunGain || free[i].kind == Free::kStart;
    (per_run ? b.own[free[i].index] : b.shared).push_back(i);
  }
  const std::vector<double> x0 = GetFree(p, m, free);
  auto values = [&](const std::vector<size_t>& idx) {
    std::vector<double> v;
    for (size_t i : idx) v.push_back(x0[i]);
    return v;
  };
  b.xs = values(b.shared);
  for (const auto& [r, idx] : b.own) b.xr[r] = values(idx);
  return b;
}

/// One run's weighted residuals as a function of its parameter blocks.
struct RunResiduals {
  const Problem* p;
  const Model* base;
  const std::vector<Free>* free;
  std::vector<const std::vector<size_t>*> blocks;  // free indices of each parameter block
  int run;
  const std::vector<double>* channel_var;
  int num_residuals = 0;
  /// The last point evaluated and its answer. Ceres asks for an accepted trial point twice in
  /// a row: its cost, then its Jacobian, whose forward differences start from the point's
  /// residuals (~6 % of a diagnosis's evaluations). The simulation is deterministic, so the
  /// repeat is answered with a copy: the same bytes. Ceres evaluates a residual block on one
  /// thread at a time.
  mutable std::vector<double> last_params;
  mutable std::vector<double> last_residuals;
  mutable bool last_ok = false;

  bool operator()(double const* const* params, double* residuals) const {
    std::vector<double> now;
    for (size_t b = 0; b < blocks.size(); ++b) now.insert(now.end(), params[b], params[b] + blocks[b]->size());
    if (!last_params.empty() && now == last_params) {
      if (last_ok) std::copy(last_residuals.begin(), last_residuals.end(), residuals);
      return last_ok;
    }
    last_ok = Evaluate(params, residuals);
    last_params = std::move(now);
    if (last_ok) last_residuals.assign(residuals, residuals + num_residuals);  // a failed one's may be unset
    return last_ok;
  }

 private:
  bool Evaluate(double const* const* params, double* residuals) const {
    Model m = *base;
    for (size_t b = 0; b < blocks.size(); ++b)
      for (size_t j = 0; j < blocks[b]->size(); ++j) SetOne(*p, m, (*free)[(*blocks[b])[j]], params[b][j]);
    try {
      const std::vector<int> one = {run};
      const auto res = ThermalResiduals(*p, m, one);
      size_t k = 0;
      for (size_t s = 0; s < res[run].size(); ++s) {
        const double sd = std::sqrt((*channel_var)[s]);
        for (double v : res[run][s]) residuals[k++] = v / sd;
      }
      // A wild trial point (an overflowing log-parameter) is a failed evaluation, not a
      // NaN that Ceres would have to be told about.
      for (size_t i = 0; i < k; ++i)
        if (!std::isfinite(residuals[i])) return false;
      return true;
    } catch (const std::exception&) {
      return false;  // e.g. CVODE failure at a wild trial point: Ceres shrinks the step
    }
  }
};

/// One residual block per run of `which` that has residuals and parameters.
void AddRunResiduals(ceres::Problem& problem, const Problem& p, const Model& base, const std::vector<Free>& free,
                     const std::vector<int>& which, const std::vector<double>& channel_var, ParameterBlocks& b) {
  // Forward differences: one simulation per parameter instead of central's two
  // (CalibrationOptions::relative_step).
  ceres::NumericDiffOptions diff;
  diff.relative_step_size = p.options.calibration.relative_step;
  for (int r : which) {
    int n_res = 0;
    for (size_t s = 0; s < p.nominal.sensors.size(); ++s)
      if (p.runs[r].sensor_col[s] >= 0) n_res += static_cast<int>(p.fit_blocks[r].size());
    RunResiduals f{&p, &base, &free, {}, r, &channel_var, n_res, {}, {}, false};
    std::vector<double*> blocks;
    if (!b.xs.empty()) f.blocks.push_back(&b.shared), blocks.push_back(b.xs.data());
    if (b.xr.count(r)) f.blocks.push_back(&b.own.at(r)), blocks.push_back(b.xr[r].data());
    if (n_res == 0 || blocks.empty()) continue;
    std::vector<int> sizes;
    for (const auto* idx : f.blocks) sizes.push_back(static_cast<int>(idx->size()));
    auto* cost = new ceres::DynamicNumericDiffCostFunction<RunResiduals, ceres::FORWARD>(
        new RunResiduals(std::move(f)), ceres::TAKE_OWNERSHIP, diff);
    for (int size : sizes) cost->AddParameterBlock(size);
    cost->SetNumResiduals(n_res);
    problem.AddResidualBlock(cost, nullptr, blocks);
  }
}

/// Priors (log-normal on knobs and gains): (x - center) / sigma on each block that has them.
void AddPriors(ceres::Problem& problem, const std::vector<Free>& free, const std::vector<int>& which, ParameterBlocks& b) {
  auto add_prior = [&](const std::vector<size_t>& idx, std::vector<double>& x) {
    std::vector<size_t> with;
    for (size_t j = 0; j < idx.size(); ++j)
      if (free[idx[j]].prior_sigma > 0.0) with.push_back(j);
    if (with.empty()) return;
    ceres::Matrix A = ceres::Matrix::Zero(static_cast<Eigen::Index>(with.size()), static_cast<Eigen::Index>(idx.size()));
    ceres::Vector c = ceres::Vector::Zero(static_cast<Eigen::Index>(idx.size()));
    for (size_t k = 0; k < with.size(); ++k) {
      const Free& f = free[idx[with[k]]];
      A(static_cast<Eigen::Index>(k), static_cast<Eigen::Index>(with[k])) = 1.0 / f.prior_sigma;
      c[static_cast<Eigen::Index>(with[k])] = f.prior_center;
    }
    problem.AddResidualBlock(new ceres::NormalPrior(A, c), nullptr, x.data());
  };
  if (!b.xs.empty()) add_prior(b.shared, b.xs);
  for (int r : which)
    if (b.xr.count(r)) add_prior(b.own.at(r), b.xr[r]);
}

/// J^T J of every residual block at the current parameter values.
Eigen::MatrixXd JtJ(ceres::Problem& problem) {
  ceres::CRSMatrix J;
  problem.Evaluate(ceres::Problem::EvaluateOptions(), nullptr, nullptr, nullptr, &J);
  Eigen::MatrixXd Jd = Eigen::MatrixXd::Zero(J.num_rows, J.num_cols);
  for (int row = 0; row < J.num_rows; ++row)
    for (int i = J.rows[row]; i < J.rows[row + 1]; ++i) Jd(row, J.cols[i]) = J.values[i];
  return Jd.transpose() * Jd;
}

}  // namespace

ThermalFit FitThermal(const Problem& p, const Model& start, const std::vector<Free>& free, const std::vector<int>& which,
                      const std::vector<double>& channel_var, int max_iterations, bool with_jtj) {
  ThermalFit out{start, {}, {}};
  if (free.empty()) return out;
  ParameterBlocks b = SplitIntoBlocks(p, start, free);
  const Model base = start;
  ceres::Problem problem;
  if (!b.xs.empty()) problem.AddParameterBlock(b.xs.data(), static_cast<int>(b.xs.size()));
  for (int r : which)
    if (b.xr.count(r)) problem.AddParameterBlock(b.xr[r].data(), static_cast<int>(b.xr[r].size()));
  AddRunResiduals(problem, p, base, free, which, channel_var, b);
  AddPriors(problem, free, which, b);

  ceres::Solver::Options opts;
  opts.linear_solver_type = ceres::DENSE_QR;
  opts.max_num_iterations = max_iterations;
  opts.logging_type = ceres::SILENT;
  opts.function_tolerance = p.options.calibration.function_tolerance;
  ceres::Solver::Summary summary;
  ceres::Solve(opts, &problem, &summary);
  out.summary = {summary.IsSolutionUsable(), summary.initial_cost, summary.final_cost,
                 static_cast<int>(summary.iterations.size())};
  if (!out.summary.usable) return out;
  for (size_t j = 0; j < b.shared.size(); ++j) SetOne(p, out.model, free[b.shared[j]], b.xs[j]);
  for (const auto& [r, idx] : b.own)
    for (size_t j = 0; j < idx.size(); ++j) SetOne(p, out.model, free[idx[j]], b.xr[r][j]);
  if (with_jtj) out.jtj = JtJ(problem);  // the shared block (knobs first) leads
  return out;
}

}  // namespace rlg::diagnosis
