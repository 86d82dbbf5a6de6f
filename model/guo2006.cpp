#include "model/guo2006.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <set>

#include "sim/errors.h"

namespace rlg::model {
namespace {

const char* kCoefficientNames[9] = {"A10", "A11", "A12", "A20", "A21", "A22", "A30", "A31", "A32"};

struct RunData {
  const std::vector<double>* t;
  const std::vector<double>* Ti;
  const std::vector<double>* Tj;
  const std::vector<double>* bias;
  double B0;
  double Ti0;
};

RunData Prepare(const sim::Run& run, const FitOptions& o) {
  for (const auto& ch : o.pair) {
    if (!run.Has(ch)) {
      throw InputError(fmt::format("run '{}' has no temperature channel '{}' (columns: {})", run.id, ch,
                                   fmt::join(run.names, ",")));
    }
  }
  const auto& Ti = run.Column(o.pair[0]);
  return {&run.t_s, &Ti, &run.Column(o.pair[1]), &run.Column("bias_dph"), InitialBias(run, o.b0_window_s), Ti.front()};
}

/// Least squares on column-scaled X: returns coefficients, their standard errors, the scaled
/// condition number and the residual RMS. Throws NumericalError naming unidentifiable columns.
struct LsResult {
  Eigen::VectorXd beta, stderr_;
  double cond = 0.0, rms = 0.0;
};

LsResult SolveLeastSquares(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, const std::vector<std::string>& names,
                           double max_cond, const std::string& hint) {
  const Eigen::Index p = X.cols(), n = X.rows();
  if (n <= p) throw NumericalError(fmt::format("{} samples cannot determine {} coefficients", n, p));
  Eigen::VectorXd scale = X.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < p; ++j) {
    if (!(scale[j] > 0.0)) {
      throw NumericalError(fmt::format("coefficient {} multiplies a regressor that is zero in every sample: {}",
                                       names[j], hint));
    }
  }
  const Eigen::MatrixXd Xs = X * scale.cwiseInverse().asDiagonal();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(Xs);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(p).triangularView<Eigen::Upper>();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  const double cond = sv[0] / sv[p - 1];
  if (!(cond < max_cond)) {
    // The right singular vector of the smallest singular value says which coefficients the
    // data cannot tell apart.
    const Eigen::VectorXd v = svd.matrixV().col(p - 1);
    std::vector<std::string> involved;
    for (Eigen::Index j = 0; j < p; ++j)
      if (std::abs(v[j]) > 0.2) involved.push_back(names[j]);
    throw NumericalError(fmt::format(
        "ill-conditioned fit (scaled condition number {:.3g}): the data cannot separate coefficients {}; {}", cond,
        fmt::join(involved, ", "), hint));
  }
  LsResult r;
  const Eigen::VectorXd beta_s = qr.solve(y);
  r.beta = beta_s.cwiseQuotient(scale);
  const Eigen::VectorXd resid = y - X * r.beta;
  r.rms = std::sqrt(resid.squaredNorm() / static_cast<double>(n));
  const double s2 = resid.squaredNorm() / static_cast<double>(n - p);
  // Cov(beta_s) = s² (R^T R)^{-1}; via the SVD of R: V S^-2 V^T.
  const Eigen::MatrixXd Rinv_cols = svd.matrixV() * sv.cwiseInverse().asDiagonal();
  r.stderr_ = (Rinv_cols.rowwise().squaredNorm().array() * s2).sqrt().matrix().cwiseQuotient(scale);
  r.cond = cond;
  return r;
}

std::string IdentifiabilityHint(const std::set<double>& t0s) {
  return fmt::format(
      "the fit has runs at {} distinct starting temperatures Ti0; the Ti0 and Ti0² terms (A_k1, A_k2) need runs "
      "at 3 or more different ambients, and the dT² and gradient terms need temperatures that change during a run",
      t0s.size());
}

}  // namespace

Eigen::Vector3d Guo2006Features(double Ti, double Tj, double Ti0) {
  const double dT = Ti - Ti0;
  return {dT, dT * dT, Tj - Ti};
}

Row9 Guo2006Row(double Ti, double Tj, double Ti0) {
  const Eigen::Vector3d f = Guo2006Features(Ti, Tj, Ti0);
  const double w[3] = {1.0, Ti0, Ti0 * Ti0};
  Row9 row;
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l) row[3 * k + l] = f[k] * w[l];
  return row;
}

Eigen::Vector3d Guo2006Coefficients::RunCoefficients(double Ti0) const {
  return A * Eigen::Vector3d(1.0, Ti0, Ti0 * Ti0);
}

double Guo2006Coefficients::Predict(double Ti, double Tj, double Ti0) const {
  return RunCoefficients(Ti0).dot(Guo2006Features(Ti, Tj, Ti0));
}

double InitialBias(const sim::Run& run, double window_s) {
  if (run.size() == 0) throw InputError(fmt::format("run '{}' is empty", run.id));
  const double t_end = run.t_s.front() + window_s;
  if (run.t_s.back() < t_end) {
    throw InputError(fmt::format("run '{}' lasts {:g} s, shorter than the {:g} s B0 window the model needs", run.id,
                                 run.t_s.back() - run.t_s.front(), window_s));
  }
  const auto& b = run.Column("bias_dph");
  double sum = 0.0;
  size_t n = 0;
  for (size_t k = 0; k < run.size() && run.t_s[k] < t_end; ++k, ++n) sum += b[k];
  return sum / static_cast<double>(n);
}

Guo2006Coefficients FitGuo2006(const std::vector<const sim::Run*>& runs, const FitOptions& o) {
  if (runs.empty()) throw InputError("fit: no runs selected");
  std::vector<RunData> data;
  size_t n = 0;
  std::set<double> t0s;
  Guo2006Coefficients c;
  c.pair = o.pair;
  c.b0_window_s = o.b0_window_s;
  c.t10_range_C = {INFINITY, -INFINITY};
  for (const sim::Run* r : runs) {
    data.push_back(Prepare(*r, o));
    n += r->size();
    t0s.insert(data.back().Ti0);
    c.runs.push_back(r->id);
    c.t10_range_C[0] = std::min(c.t10_range_C[0], data.back().Ti0);
    c.t10_range_C[1] = std::max(c.t10_range_C[1], data.back().Ti0);
  }
  const std::string hint = IdentifiabilityHint(t0s);
  const std::vector<std::string> names9(std::begin(kCoefficientNames), std::end(kCoefficientNames));

  if (o.method == FitOptions::Method::kJoint) {
    c.method = "joint";
    Eigen::MatrixXd X(static_cast<Eigen::Index>(n), 9);
    Eigen::VectorXd y(static_cast<Eigen::Index>(n));
    Eigen::Index row = 0;
    for (const auto& d : data) {
      for (size_t k = 0; k < d.t->size(); ++k, ++row) {
        X.row(row) = Guo2006Row((*d.Ti)[k], (*d.Tj)[k], d.Ti0).transpose();
        y[row] = (*d.bias)[k] - d.B0;
      }
    }
    const LsResult r = SolveLeastSquares(X, y, names9, o.max_condition_number, hint);
    for (int k = 0; k < 3; ++k) {
      for (int l = 0; l < 3; ++l) {
        c.A(k, l) = r.beta[3 * k + l];
        c.A_stderr(k, l) = r.stderr_[3 * k + l];
      }
    }
    c.condition_number = r.cond;
    c.residual_rms_dph = r.rms;
    return c;
  }

  // Two-stage: per-run a_k, then a quadratic in Ti0 for each k.
  c.method = "two_stage";
  if (t0s.size() < 3) throw NumericalError(fmt::format("two-stage fit: {}", hint));
  const std::vector<std::string> names3 = {"a1", "a2", "a3"};
  Eigen::MatrixXd a(static_cast<Eigen::Index>(data.size()), 3);
  Eigen::MatrixXd W(static_cast<Eigen::Index>(data.size()), 3);
  double cond = 0.0;
  for (size_t r = 0; r < data.size(); ++r) {
    const auto& d = data[r];
    const auto m = static_cast<Eigen::Index>(d.t->size());
    Eigen::MatrixXd X(m, 3);
    Eigen::VectorXd y(m);
    for (Eigen::Index k = 0; k < m; ++k) {
      X.row(k) = Guo2006Features((*d.Ti)[k], (*d.Tj)[k], d.Ti0).transpose();
      y[k] = (*d.bias)[k] - d.B0;
    }
    const LsResult lr = SolveLeastSquares(X, y, names3, o.max_condition_number,
                                          fmt::format("run '{}': the temperatures must change during the run", runs[r]->id));
    a.row(static_cast<Eigen::Index>(r)) = lr.beta.transpose();
    W.row(static_cast<Eigen::Index>(r)) << 1.0, d.Ti0, d.Ti0 * d.Ti0;
    cond = std::max(cond, lr.cond);
  }
  double rms_sse = 0.0;
  for (int k = 0; k < 3; ++k) {
    const LsResult lr = SolveLeastSquares(W, a.col(k), {fmt::format("A{}0", k + 1), fmt::format("A{}1", k + 1),
                                                         fmt::format("A{}2", k + 1)},
                                          o.max_condition_number, hint);
    c.A.row(k) = lr.beta.transpose();
    c.A_stderr.row(k) = lr.stderr_.transpose();
    cond = std::max(cond, lr.cond);
  }
  // Residual of the final (stage-2) model over all samples.
  size_t count = 0;
  for (const auto& d : data) {
    for (size_t k = 0; k < d.t->size(); ++k, ++count) {
      const double e = (*d.bias)[k] - d.B0 - c.Predict((*d.Ti)[k], (*d.Tj)[k], d.Ti0);
      rms_sse += e * e;
    }
  }
  c.condition_number = cond;
  c.residual_rms_dph = std::sqrt(rms_sse / static_cast<double>(count));
  return c;
}

}  // namespace rlg::model
