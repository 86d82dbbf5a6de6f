#include "model/guo2006.h"

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

#include "sim/errors.h"

namespace rlg::model {
namespace {

const char* kCoefficientNames[9] = {"A10", "A11", "A12", "A20", "A21", "A22", "A30", "A31", "A32"};

/// One run reduced to what both fits need. With F = [1, dT, dT², Tj - Ti] (n x 4), the 1 for
/// the run's own offset, and y = bias - B0, the Householder QR of [F y] gives R (5 x 5). Its
/// rows 1..3 past the offset column, R3 = R(1..3, 1..3) and z = R(1..3, 4), carry every sample's
/// information on the run's a_k with the offset profiled out: the least squares of the run is
/// min |z - R3 a|², and ssr = R(4, 4)² is its residual (n - 4 degrees of freedom). Rows are
/// signed so that diag(R3) >= 0: the three directions then mean the same in every run, which
/// the run-scatter errors of the joint fit rely on.
struct ReducedRun {
  double Ti0 = 0.0;
  double n = 0.0;
  Eigen::Matrix3d R3;
  Eigen::Vector3d z;
  double ssr = 0.0;
};

ReducedRun Reduce(const sim::Run& run, const FitOptions& o) {
  for (const auto& ch : o.pair) {
    if (!run.Has(ch)) {
      throw InputError(fmt::format("run '{}' has no temperature channel '{}' (columns: {})", run.id, ch,
                                   fmt::join(run.names, ",")));
    }
  }
  const double B0 = InitialBias(run, o.b0_window_s);
  const auto len = static_cast<Eigen::Index>(run.size());
  if (len < 5) {
    throw InputError(fmt::format("run '{}' has {} samples; the Eq. (2) fit needs at least 5 per run: 4 for the run's "
                                 "bias level and three temperature terms, 1 more for the noise",
                                 run.id, len));
  }
  const auto& Ti = run.Column(o.pair[0]);
  const auto& Tj = run.Column(o.pair[1]);
  const auto& bias = run.Column("bias_dph");
  ReducedRun rr;
  rr.Ti0 = Ti.front();
  rr.n = static_cast<double>(len);
  Eigen::MatrixXd Fy(len, 5);
  for (Eigen::Index k = 0; k < len; ++k) {
    const auto i = static_cast<size_t>(k);
    Fy(k, 0) = 1.0;
    Fy.block<1, 3>(k, 1) = Guo2006Features(Ti[i], Tj[i], rr.Ti0).transpose();
    Fy(k, 4) = bias[i] - B0;
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(Fy);
  const Eigen::Matrix<double, 5, 5> R = qr.matrixQR().topRows<5>().triangularView<Eigen::Upper>();
  rr.R3 = R.block<3, 3>(1, 1);
  rr.z = R.block<3, 1>(1, 4);
  for (int i = 0; i < 3; ++i) {
    if (rr.R3(i, i) < 0.0) {
      rr.R3.row(i) *= -1.0;
      rr.z[i] *= -1.0;
    }
  }
  rr.ssr = R(4, 4) * R(4, 4);
  return rr;
}

/// Least squares on column-scaled X (Householder QR; the condition number from the SVD of R).
/// X may also be a compressed problem with the same X^T X and X^T y as the full one (see the
/// joint fit). Returns the coefficients, a square root G of (X^T X)^-1 = G G^T for their
/// covariances, and the scaled condition number. Throws NumericalError naming the coefficients
/// the data cannot see.
struct LsResult {
  Eigen::VectorXd beta;
  Eigen::MatrixXd G;
  double cond = 0.0;
  /// diag((X^T X)^-1): squared standard errors per unit noise variance.
  Eigen::VectorXd UnitVariance() const { return G.rowwise().squaredNorm(); }
};

LsResult SolveLeastSquares(const Eigen::MatrixXd& X, const Eigen::VectorXd& y, const std::vector<std::string>& names,
                           double max_cond, const std::string& hint) {
  const Eigen::Index p = X.cols(), n = X.rows();
  if (n < p) throw NumericalError(fmt::format("{} equations cannot determine {} coefficients: {}", n, p, hint));
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
  // (R^T R)^-1 = V S^-2 V^T from the SVD of R; undo the column scaling.
  r.G = scale.cwiseInverse().asDiagonal() * svd.matrixV() * sv.cwiseInverse().asDiagonal();
  r.cond = cond;
  return r;
}

/// The run-scatter error model of the joint fit. Each run's projected errors e_r = z_r - R3_r a_r
/// get one covariance C (3 x 3) common to all runs. The residuals r of the compressed problem
/// (3 rows a run, hat matrix H = U U^T, U = S G, P = I - H) have
/// E[sum_r r_r r_r^T] = sum_{r,s} P_rs C P_rs^T, linear in C: vec form L vec(C), with
/// L = sum_{r,s} P_rs (x) P_rs = m I - sum_r (H_rr (x) I + I (x) H_rr) + T T^T,
/// T(i + 3j, a + 9b) = sum_r U_r(i,a) U_r(j,b): O(runs), no 3m x 3m matrix.
Eigen::Matrix<double, 9, 9> ScatterMoments(const Eigen::MatrixXd& U) {
  const Eigen::Index m = U.rows() / 3;
  Eigen::Matrix<double, 9, 9> L = static_cast<double>(m) * Eigen::Matrix<double, 9, 9>::Identity();
  Eigen::Matrix<double, 9, 81> T = Eigen::Matrix<double, 9, 81>::Zero();
  for (Eigen::Index r = 0; r < m; ++r) {
    const Eigen::Matrix<double, 3, 9> Ur = U.middleRows<3>(3 * r);
    const Eigen::Matrix3d Hrr = Ur * Ur.transpose();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l)
            L(i + 3 * j, k + 3 * l) -= (i == k ? Hrr(j, l) : 0.0) + (j == l ? Hrr(i, k) : 0.0);
        for (int a = 0; a < 9; ++a)
          for (int b = 0; b < 9; ++b) T(i + 3 * j, a + 9 * b) += Ur(i, a) * Ur(j, b);
      }
  }
  L.noalias() += T * T.transpose();
  return L;
}

/// C from the residuals: the unbiased moment estimate L^-1 vec(sum_r r_r r_r^T), symmetrised
/// and clipped to be positive semi-definite.
Eigen::Matrix3d CommonRunCovariance(const Eigen::Matrix<double, 9, 9>& L, const Eigen::VectorXd& residual) {
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (Eigen::Index r = 0; r < residual.size() / 3; ++r) {
    const Eigen::Vector3d rr = residual.segment<3>(3 * r);
    M.noalias() += rr * rr.transpose();
  }
  const Eigen::Matrix<double, 9, 1> c =
      L.colPivHouseholderQr().solve(Eigen::Map<const Eigen::Matrix<double, 9, 1>>(M.data()));
  const Eigen::Matrix3d C = Eigen::Map<const Eigen::Matrix3d>(c.data());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (C + C.transpose()));
  return eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
}

/// Satterthwaite degrees of freedom of the run-scatter variance v = tr(C_hat Q) of one
/// coefficient (Q = sum_r u_r u_r^T, u_r = U_r g, g its row of G): v = sum_r r_r^T D r_r with
/// vec(D) = L^-T vec(Q), a quadratic form in the residuals r = P e. With e ~ N(0, I (x) C),
/// E[v] = tr(D P C P) (= tr(C Q): the estimate is unbiased), Var[v] = 2 tr((D P C P)^2), and
/// dof = 2 E[v]^2 / Var[v]. Evaluated at the working model C = I (white noise), as Bell and
/// McCaffrey do for cluster-robust errors: a plug-in C_hat from 4-6 runs is too rough (it gave
/// dof ~1e-3). With C = I and P = I - U U^T idempotent, writing D for I (x) D and
/// S = U^T D U = sum_r U_r^T D U_r:
///   E[v] = tr(D P) = m tr(D) - tr(S),  Var[v] / 2 = tr(D P D P) = m tr(D²) - 2 tr(U^T D² U) + tr(S²).
double ScatterDof(const Eigen::MatrixXd& U, const Eigen::Matrix<double, 9, 9>& L, const Eigen::Matrix3d& Q) {
  const Eigen::Matrix<double, 9, 1> d =
      L.transpose().colPivHouseholderQr().solve(Eigen::Map<const Eigen::Matrix<double, 9, 1>>(Q.data()));
  const Eigen::Matrix3d D0 = Eigen::Map<const Eigen::Matrix3d>(d.data());
  const Eigen::Matrix3d D = 0.5 * (D0 + D0.transpose());
  const Eigen::Matrix3d D2 = D * D;
  const auto m = static_cast<double>(U.rows() / 3);
  Eigen::Matrix<double, 9, 9> S = Eigen::Matrix<double, 9, 9>::Zero();
  double tr_D2_sandwich = 0.0;
  for (Eigen::Index r = 0; r < U.rows() / 3; ++r) {
    const Eigen::Matrix<double, 3, 9> Ur = U.middleRows<3>(3 * r);
    S.noalias() += Ur.transpose() * D * Ur;
    tr_D2_sandwich += (D2 * Ur * Ur.transpose()).trace();
  }
  const double mean = m * D.trace() - S.trace();
  const double half_var = m * D2.trace() - 2.0 * tr_D2_sandwich + (S * S).trace();
  const double dof = mean * mean / half_var;
  // Below 1 a t interval is wider than any data could support; also catches a degenerate L.
  return std::isfinite(dof) ? std::max(dof, 1.0) : 1.0;
}

/// Starting temperatures closer than this count as one ambient (sensor noise and resolution
/// make repeated soaks differ by a few hundredths of a degree).
constexpr double kSameAmbient_C = 0.5;

/// Runs grouped by start temperature: sorted Ti0, a new group where the gap exceeds kSameAmbient_C.
struct StartTemperature {
  double Ti0_C;  ///< of the group's first (coldest) run
  std::vector<std::string> runs;
};

std::vector<StartTemperature> StartTemperatures(const std::vector<const sim::Run*>& runs,
                                                const std::vector<double>& t0s) {
  std::vector<size_t> order(t0s.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return t0s[a] < t0s[b]; });
  std::vector<StartTemperature> groups;
  for (size_t k = 0; k < order.size(); ++k) {
    const size_t i = order[k];
    if (k == 0 || t0s[i] - t0s[order[k - 1]] > kSameAmbient_C) groups.push_back({t0s[i], {}});
    groups.back().runs.push_back(runs[i]->id);
  }
  return groups;
}

/// Eq. (2)'s a_k are quadratics in Ti0: fewer than three start temperatures cannot give them.
std::string TooFewStartTemperatures(const std::vector<StartTemperature>& groups, size_t runs) {
  std::vector<std::string> listed;
  for (const auto& g : groups) {
    const size_t shown = std::min<size_t>(g.runs.size(), 4);
    const std::vector<std::string> ids(g.runs.begin(), g.runs.begin() + static_cast<std::ptrdiff_t>(shown));
    listed.push_back(fmt::format("{:.2f} °C ({}{})", g.Ti0_C, fmt::join(ids, ", "),
                                 g.runs.size() > shown ? fmt::format(" and {} more", g.runs.size() - shown) : ""));
  }
  const char* unseen = groups.size() == 1 ? "A11, A12, A21, A22, A31, A32 (the Ti0 and Ti0² terms)"
                                          : "A10, A11, A12, A20, A21, A22, A30, A31, A32 (two start temperatures fit "
                                            "a line in Ti0, not a quadratic)";
  return fmt::format(
      "the data cannot separate coefficients {}: Eq. (2) needs runs at 3 or more different start temperatures Ti0 "
      "(3 or more different ambients; a_k = A_k0 + A_k1 Ti0 + A_k2 Ti0²), and the data has {} run{} at {} start "
      "temperature{} (Ti0 within {:g} °C counted as one): {}. Add runs started after a soak at other ambients",
      unseen, runs, runs == 1 ? "" : "s", groups.size(), groups.size() == 1 ? "" : "s", kSameAmbient_C,
      fmt::join(listed, "; "));
}

std::string IdentifiabilityHint(size_t start_temperatures) {
  return fmt::format(
      "the fit has runs at {} distinct start temperatures Ti0 (within {:g} °C counted as one); the Ti0 and Ti0² "
      "terms (A_k1, A_k2) need runs at 3 or more different ambients, and the dT² and gradient terms need "
      "temperatures that change during a run",
      start_temperatures, kSameAmbient_C);
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

Eigen::Matrix3d Guo2006Coefficients::ConfidenceHalfWidth(double level) const {
  if (!(level > 0.0 && level < 1.0)) {
    throw std::invalid_argument(fmt::format("confidence level {} not in (0, 1)", level));
  }
  if (!(stderr_dof.minCoeff() > 0.0)) throw std::logic_error("ConfidenceHalfWidth: stderr_dof must be positive");
  Eigen::Matrix3d hw;
  for (int k = 0; k < 3; ++k)
    for (int l = 0; l < 3; ++l)
      hw(k, l) = boost::math::quantile(boost::math::students_t(stderr_dof(k, l)), 0.5 + 0.5 * level) * A_stderr(k, l);
  return hw;
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
  std::vector<ReducedRun> data;
  std::vector<double> t0s;
  Guo2006Coefficients c;
  c.pair = o.pair;
  c.b0_window_s = o.b0_window_s;
  c.t10_range_C = {INFINITY, -INFINITY};
  double n = 0.0, ssr_within = 0.0;
  for (const sim::Run* r : runs) {
    data.push_back(Reduce(*r, o));
    n += data.back().n;
    ssr_within += data.back().ssr;
    t0s.push_back(data.back().Ti0);
    c.runs.push_back(r->id);
    c.t10_range_C[0] = std::min(c.t10_range_C[0], data.back().Ti0);
    c.t10_range_C[1] = std::max(c.t10_range_C[1], data.back().Ti0);
  }
  const std::vector<StartTemperature> groups = StartTemperatures(runs, t0s);
  if (groups.size() < 3) throw NumericalError(TooFewStartTemperatures(groups, runs.size()));
  const std::string hint = IdentifiabilityHint(groups.size());
  const std::vector<std::string> names9(std::begin(kCoefficientNames), std::end(kCoefficientNames));
  const auto m = static_cast<Eigen::Index>(data.size());
  // Within-run white-noise variance (each run's own 4-parameter fit): the errors' source when
  // three runs leave no scatter between them. Reduce() guarantees n_r >= 5, so dof >= m.
  const double dof_within = n - 4.0 * static_cast<double>(m);
  const double var_within = ssr_within / dof_within;
  const bool run_scatter = m > 3;
  c.stderr_method = run_scatter ? "run_scatter" : "within_run_white";
  c.stderr_dof.setConstant(run_scatter ? static_cast<double>(m - 3) : dof_within);

  auto finish = [&](double cond) {
    c.condition_number = cond;
    double ssr = 0.0;  // Eq. (3) with the paper's B0 over every sample
    for (const sim::Run* r : runs) ssr += RunSse(c, *r);
    c.residual_rms_dph = std::sqrt(ssr / n);
    return c;
  };

  if (o.method == FitOptions::Method::kJoint) {
    c.method = "joint";
    // The rows of a run are f ⊗ w(Ti0) with w = [1, Ti0, Ti0²] constant in the run, so after
    // Reduce() the run's samples carry exactly the information of the 3 rows R3 (I3 ⊗ w^T) with
    // right-hand side z: the joint problem shrinks to 3 rows per run, orthogonal
    // transformations only (no normal equations), O(samples) in all.
    Eigen::MatrixXd S(3 * m, 9);
    Eigen::VectorXd z(3 * m);
    for (Eigen::Index r = 0; r < m; ++r) {
      const ReducedRun& d = data[static_cast<size_t>(r)];
      const double w[3] = {1.0, d.Ti0, d.Ti0 * d.Ti0};
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) S(3 * r + i, 3 * k + l) = d.R3(i, k) * w[l];
      z.segment<3>(3 * r) = d.z;
    }
    const LsResult ls = SolveLeastSquares(S, z, names9, o.max_condition_number, hint);
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) c.A(k, l) = ls.beta[3 * k + l];
    // beta - beta_true = G U^T e with U = S G: Cov = G (sum_r U_r^T C U_r) G^T.
    const Eigen::MatrixXd U = S * ls.G;
    Eigen::Matrix<double, 9, 9> L;
    Eigen::Matrix3d C = var_within * Eigen::Matrix3d::Identity();
    if (run_scatter) {
      L = ScatterMoments(U);
      C = CommonRunCovariance(L, z - S * ls.beta);
    }
    for (int j = 0; j < 9; ++j) {
      const Eigen::Matrix<double, 9, 1> g = ls.G.row(j).transpose();
      Eigen::Matrix3d Q = Eigen::Matrix3d::Zero();
      for (Eigen::Index r = 0; r < m; ++r) {
        const Eigen::Vector3d u = U.middleRows<3>(3 * r) * g;
        Q.noalias() += u * u.transpose();
      }
      c.A_stderr(j / 3, j % 3) = std::sqrt((C * Q).trace());
      c.stderr_dof(j / 3, j % 3) = run_scatter ? ScatterDof(U, L, Q) : dof_within;
    }
    return finish(ls.cond);
  }

  // Two-stage: per-run a_k, then a quadratic in Ti0 for each k.
  c.method = "two_stage";
  const std::vector<std::string> names3 = {"a1", "a2", "a3"};
  Eigen::MatrixXd a(m, 3), W(m, 3);
  std::vector<Eigen::Matrix3d> run_unit_cov(data.size());
  double cond = 0.0;
  for (Eigen::Index r = 0; r < m; ++r) {
    const ReducedRun& d = data[static_cast<size_t>(r)];
    const LsResult lr = SolveLeastSquares(
        d.R3, d.z, names3, o.max_condition_number,
        fmt::format("run '{}': the temperatures must change during the run", runs[static_cast<size_t>(r)]->id));
    a.row(r) = lr.beta.transpose();
    run_unit_cov[static_cast<size_t>(r)] = lr.G * lr.G.transpose();
    W.row(r) << 1.0, d.Ti0, d.Ti0 * d.Ti0;
    cond = std::max(cond, lr.cond);
  }
  for (int k = 0; k < 3; ++k) {
    const LsResult lr = SolveLeastSquares(W, a.col(k), {fmt::format("A{}0", k + 1), fmt::format("A{}1", k + 1),
                                                         fmt::format("A{}2", k + 1)},
                                          o.max_condition_number, hint);
    c.A.row(k) = lr.beta.transpose();
    if (run_scatter) {
      // The scatter of the per-run a_k about the quadratic, m - 3 degrees of freedom.
      const double ssr2 = (a.col(k) - W * lr.beta).squaredNorm();
      c.A_stderr.row(k) = (lr.UnitVariance() * (ssr2 / static_cast<double>(m - 3))).cwiseSqrt().transpose();
    } else {
      // A_k = P a_k with P = (W^T W)^-1 W^T; the runs' a_k errors are independent.
      const Eigen::MatrixXd P = lr.G * lr.G.transpose() * W.transpose();
      Eigen::Vector3d var = Eigen::Vector3d::Zero();
      for (Eigen::Index r = 0; r < m; ++r)
        var += P.col(r).cwiseAbs2() * (var_within * run_unit_cov[static_cast<size_t>(r)](k, k));
      c.A_stderr.row(k) = var.cwiseSqrt().transpose();
    }
    cond = std::max(cond, lr.cond);
  }
  return finish(cond);
}

}  // namespace rlg::model
