#include "model/guo2006.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>

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
      throw InputError(fmt::format("{} has no temperature channel '{}' (columns: {})", run.Where(), ch,
                                   fmt::join(run.names, ",")));
    }
  }
  const auto& Ti = run.Column(o.pair[0]);
  return {&run.t_s, &Ti, &run.Column(o.pair[1]), &run.Column("bias_dph"), InitialBias(run, o.b0_window_s), Ti.front()};
}

/// Least squares on column-scaled X (Householder QR; the condition number from the SVD of R).
/// X may also be a compressed problem with the same X^T X and X^T y as the full one (see the
/// joint fit). Returns the coefficients, diag((X^T X)^-1) for their standard errors, and the
/// scaled condition number. Throws NumericalError naming the coefficients the data cannot see.
struct LsResult {
  Eigen::VectorXd beta, unit_variance;
  double cond = 0.0;
  /// Standard errors for residual sum of squares ssr over n samples.
  Eigen::VectorXd StdErr(double ssr, double n) const {
    return (unit_variance * (ssr / (n - static_cast<double>(beta.size())))).cwiseSqrt();
  }
};

LsResult SolveLeastSquares(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, const std::vector<std::string>& names,
                           double max_cond, const std::string& hint) {
  const Eigen::Index p = X.cols(), n = X.rows();
  if (n < p) throw NumericalError(fmt::format("{} samples cannot determine {} coefficients", n, p));
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
    // The right singular vectors of the (near-)zero singular values span what the data cannot
    // see: name every coefficient that takes part in them.
    std::vector<std::string> involved;
    for (Eigen::Index j = 0; j < p; ++j) {
      bool in_null_space = false;
      for (Eigen::Index s = 0; s < p; ++s) {
        if (sv[s] * max_cond < sv[0] && std::abs(svd.matrixV()(j, s)) > 0.2) in_null_space = true;
      }
      if (in_null_space) involved.push_back(names[j]);
    }
    throw NumericalError(fmt::format(
        "ill-conditioned fit (scaled condition number {:.3g}): the data cannot separate coefficients {}; {}", cond,
        fmt::join(involved, ", "), hint));
  }
  LsResult r;
  const Eigen::VectorXd beta_s = qr.solve(y);
  r.beta = beta_s.cwiseQuotient(scale);
  // (R^T R)^{-1} = V S^-2 V^T from the SVD of R; undo the column scaling.
  const Eigen::MatrixXd Rinv_cols = svd.matrixV() * sv.cwiseInverse().asDiagonal();
  r.unit_variance = Rinv_cols.rowwise().squaredNorm().cwiseQuotient(scale.cwiseProduct(scale));
  r.cond = cond;
  return r;
}

/// Starting temperatures closer than this count as one ambient (sensor noise and resolution
/// make repeated soaks differ by a few hundredths of a degree).
constexpr double kSameAmbient_C = 0.5;

size_t DistinctAmbients(std::vector<double> t0s) {
  std::sort(t0s.begin(), t0s.end());
  size_t n = 0;
  for (size_t i = 0; i < t0s.size(); ++i)
    if (i == 0 || t0s[i] - t0s[i - 1] > kSameAmbient_C) ++n;
  return n;
}

std::string IdentifiabilityHint(const std::vector<double>& t0s) {
  return fmt::format(
      "the fit has runs at {} distinct starting temperatures Ti0 (within {:g} °C counted as one); the Ti0 and Ti0² "
      "terms (A_k1, A_k2) need runs at 3 or more different ambients, and the dT² and gradient terms need "
      "temperatures that change during a run",
      DistinctAmbients(t0s), kSameAmbient_C);
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
  if (run.size() == 0) throw InputError(fmt::format("{} is empty", run.Where()));
  const double t_end = run.t_s.front() + window_s;
  if (run.t_s.back() < t_end) {
    throw InputError(fmt::format("{} lasts {:g} s, shorter than the {:g} s B0 window the model needs", run.Where(),
                                 run.t_s.back() - run.t_s.front(), window_s));
  }
  const auto& b = run.Column("bias_dph");
  double sum = 0.0;
  size_t n = 0;
  for (size_t k = 0; k < run.size() && run.t_s[k] < t_end; ++k, ++n) sum += b[k];
  return sum / static_cast<double>(n);
}

double RunSse(const Guo2006Coefficients& c, const sim::Run& run) {
  const auto& Ti = run.Column(c.pair[0]);
  const auto& Tj = run.Column(c.pair[1]);
  const auto& b = run.Column("bias_dph");
  const double B0 = InitialBias(run, c.b0_window_s);
  double sse = 0.0;
  for (size_t k = 0; k < run.size(); ++k) {
    const double e = b[k] - B0 - c.Predict(Ti[k], Tj[k], Ti.front());
    sse += e * e;
  }
  return sse;
}

Guo2006Coefficients FitGuo2006(const std::vector<const sim::Run*>& runs, const FitOptions& o) {
  if (runs.empty()) throw InputError("fit: no runs selected");
  std::vector<RunData> data;
  size_t n = 0;
  std::vector<double> t0s;
  Guo2006Coefficients c;
  c.pair = o.pair;
  c.b0_window_s = o.b0_window_s;
  c.t10_range_C = {INFINITY, -INFINITY};
  for (const sim::Run* r : runs) {
    data.push_back(Prepare(*r, o));
    n += r->size();
    t0s.push_back(data.back().Ti0);
    c.runs.push_back(r->id);
    c.t10_range_C[0] = std::min(c.t10_range_C[0], data.back().Ti0);
    c.t10_range_C[1] = std::max(c.t10_range_C[1], data.back().Ti0);
  }
  const std::string hint = IdentifiabilityHint(t0s);
  const std::vector<std::string> names9(std::begin(kCoefficientNames), std::end(kCoefficientNames));

  // Residual sum of squares of a coefficient matrix over all samples (exact, O(n)).
  auto ssr_of = [&](const Guo2006Coefficients& model) {
    double ssr = 0.0;
    for (const sim::Run* r : runs) ssr += RunSse(model, *r);
    return ssr;
  };

  if (o.method == FitOptions::Method::kJoint) {
    c.method = "joint";
    // The rows of a run are f ⊗ w(Ti0) with w constant in the run, so X_r = F_r (I3 ⊗ w^T).
    // With F_r = Q_r R_r (thin QR, n_r x 3), the 3 rows R_r (I3 ⊗ w^T) and right-hand side
    // Q_r^T y_r carry the same X^T X and X^T y as the run's n_r rows: the joint problem shrinks
    // to 3 rows per run, orthogonal transformations only (no normal equations), O(n) in all.
    const auto m = static_cast<Eigen::Index>(data.size());
    Eigen::MatrixXd S(3 * m, 9);
    Eigen::VectorXd z(3 * m);
    for (Eigen::Index r = 0; r < m; ++r) {
      const auto& d = data[static_cast<size_t>(r)];
      const auto len = static_cast<Eigen::Index>(d.t->size());
      Eigen::MatrixXd F(len, 3);
      Eigen::VectorXd y(len);
      for (Eigen::Index k = 0; k < len; ++k) {
        F.row(k) = Guo2006Features((*d.Ti)[k], (*d.Tj)[k], d.Ti0).transpose();
        y[k] = (*d.bias)[k] - d.B0;
      }
      const Eigen::HouseholderQR<Eigen::MatrixXd> qr(F);
      const Eigen::Matrix3d R = qr.matrixQR().topLeftCorner(3, 3).triangularView<Eigen::Upper>();
      const Eigen::VectorXd qty = (qr.householderQ().transpose() * y).head(3);
      const double w[3] = {1.0, d.Ti0, d.Ti0 * d.Ti0};
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) S(3 * r + i, 3 * k + l) = R(i, k) * w[l];
      z.segment(3 * r, 3) = qty;
    }
    const LsResult r = SolveLeastSquares(S, z, names9, o.max_condition_number, hint);
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) c.A(k, l) = r.beta[3 * k + l];
    const double ssr = ssr_of(c);
    const Eigen::VectorXd se = r.StdErr(ssr, static_cast<double>(n));
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) c.A_stderr(k, l) = se[3 * k + l];
    c.condition_number = r.cond;
    c.residual_rms_dph = std::sqrt(ssr / static_cast<double>(n));
    return c;
  }

  // Two-stage: per-run a_k, then a quadratic in Ti0 for each k.
  c.method = "two_stage";
  if (DistinctAmbients(t0s) < 3) throw NumericalError(fmt::format("two-stage fit: {}", hint));
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
                                          fmt::format("{}: the temperatures must change during the run", runs[r]->Where()));
    a.row(static_cast<Eigen::Index>(r)) = lr.beta.transpose();
    W.row(static_cast<Eigen::Index>(r)) << 1.0, d.Ti0, d.Ti0 * d.Ti0;
    cond = std::max(cond, lr.cond);
  }
  for (int k = 0; k < 3; ++k) {
    const LsResult lr = SolveLeastSquares(W, a.col(k), {fmt::format("A{}0", k + 1), fmt::format("A{}1", k + 1),
                                                         fmt::format("A{}2", k + 1)},
                                          o.max_condition_number, hint);
    c.A.row(k) = lr.beta.transpose();
    // Stage-2 errors: the scatter of the per-run a_k about the quadratic.
    const double ssr2 = (a.col(k) - W * lr.beta).squaredNorm();
    c.A_stderr.row(k) = lr.StdErr(ssr2, static_cast<double>(W.rows())).transpose();
    cond = std::max(cond, lr.cond);
  }
  c.condition_number = cond;
  c.residual_rms_dph = std::sqrt(ssr_of(c) / static_cast<double>(n));
  return c;
}

}  // namespace rlg::model
