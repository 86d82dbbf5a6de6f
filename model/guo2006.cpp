#include "model/guo2006.h"

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <fmt/format.h>
#include <stdexcept>

#include "model/streaming_qr.h"
#include "sim/errors.h"

namespace rlg::model {
namespace {

const char* kCoefficientNames[9] = {"A10", "A11", "A12", "A20", "A21", "A22", "A30", "A31", "A32"};

/// One run reduced to what both fits need. With F = [dT, dT², Tj - Ti] (n x 3) and
/// y = bias - B0, the Householder QR of [F y 1 u] (u: the B0 window's averaging weights, 1/n_W
/// on its samples) gives R, of which rows 0..3 are needed: R3 = R(0..2, 0..2) and
/// z = R(0..2, 3) carry every sample's information on the run's a_k (its least squares is
/// min |z - R3 a|²), ssr = R(3, 3)² is that fit's residual, and v = R(0..2, 4) = Q3^T 1,
/// w = R(0..2, 5) = Q3^T u give the errors' covariance under white noise
/// (WhiteNoiseCovariance). Rows are signed so that diag(R3) >= 0: the three directions then
/// mean the same in every run, which the run-scatter errors rely on.
struct ReducedRun {
  double Ti0 = 0.0;
  double n = 0.0;
  Eigen::Matrix3d R3;
  Eigen::Vector3d z, v, w;
  double ssr = 0.0;
  double n_window = 0.0;
};

ReducedRun Reduce(const sim::Run& run, const FitOptions& o) {
  for (const auto& ch : o.pair) {
    if (!run.Has(ch)) {
      throw InputError(fmt::format("{} has no temperature channel '{}' (columns: {})", run.Where(), ch,
                                   fmt::join(run.names, ",")));
    }
  }
  const double B0 = InitialBias(run, o.b0_window_s);
  const auto len = static_cast<Eigen::Index>(run.size());
  if (len < 4) {
    throw InputError(fmt::format("{} has {} samples; the Eq. (2) fit needs at least 4 per run: 3 for its "
                                 "temperature terms and 1 more for the noise",
                                 run.Where(), len));
  }
  const auto& Ti = run.Column(o.pair[0]);
  const auto& Tj = run.Column(o.pair[1]);
  const auto& bias = run.Column("bias_dph");
  ReducedRun rr;
  rr.Ti0 = Ti.front();
  rr.n = static_cast<double>(len);
  const double t_end = run.t_s.front() + o.b0_window_s;
  // Counted in an integer: a sum of doubles would be one addition chain through the run.
  size_t in_window = 0;
  for (const double t : run.t_s) in_window += t < t_end ? 1 : 0;
  rr.n_window = static_cast<double>(in_window);  // >= 1: InitialBias averaged over these
  const double u = 1.0 / rr.n_window;
  // The samples' rows streamed through the QR (model/streaming_qr.h): the n x 6 matrix is never
  // stored, and on paper-fixed's runs R came 10-100x closer to a QR in long double than Eigen's
  // HouseholderQR of the whole matrix (errors ~5e-16 against 1e-14 to 9e-14 of each column's
  // norm: the columns dT², 1 and u have large means, and Eigen sums over all 7,201 rows).
  StreamingQr<6, 4> qr;  // R's rows 0..3: those below are the columns 1 and u's own
  for (size_t i = 0; i < run.size(); ++i) {
    const Eigen::Vector3d f = Guo2006Features(Ti[i], Tj[i], rr.Ti0);
    qr.Add({f[0], f[1], f[2], bias[i] - B0, 1.0, run.t_s[i] < t_end ? u : 0.0});
  }
  const Eigen::Matrix<double, 4, 6> R = qr.R();
  rr.R3 = R.topLeftCorner<3, 3>();
  rr.z = R.block<3, 1>(0, 3);
  rr.v = R.block<3, 1>(0, 4);
  rr.w = R.block<3, 1>(0, 5);
  for (int i = 0; i < 3; ++i) {
    if (rr.R3(i, i) < 0.0) {
      rr.R3.row(i) *= -1.0;
      rr.z[i] *= -1.0;
      rr.v[i] *= -1.0;
      rr.w[i] *= -1.0;
    }
  }
  rr.ssr = R(3, 3) * R(3, 3);
  return rr;
}

/// Cov(z - R3 a) / sigma² of a run under white noise of variance sigma², B0's error included:
/// y = F a + M e with M = I - 1 u^T, z = Q3^T y, so Cov = Q3^T M M^T Q3 = I - v w^T - w v^T +
/// v v^T / n_window (u^T u = 1 / n_window).
Eigen::Matrix3d WhiteNoiseCovariance(const ReducedRun& d) {
  return Eigen::Matrix3d::Identity() - d.v * d.w.transpose() - d.w * d.v.transpose() +
         d.v * d.v.transpose() / d.n_window;
}

/// sigma² of white noise from the runs' own residuals, unbiased: E[ssr_r] = sigma² tr((I - H) M M^T)
/// = sigma² (n - 2 + n / n_window - tr(WhiteNoiseCovariance)), H the projection on the run's F
/// (tr(M M^T) = n - 2 + n / n_window).
double WhiteNoiseVariance(const std::vector<ReducedRun>& data) {
  double ssr = 0.0, expected = 0.0;
  for (const auto& d : data) {
    ssr += d.ssr;
    expected += d.n - 2.0 + d.n / d.n_window - WhiteNoiseCovariance(d).trace();
  }
  return ssr / expected;
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

/// The run-scatter error model of the joint fit. The compressed problem has 3 rows a run; its
/// residuals are r = P e, P = I - U U^T (U = S G, orthonormal columns), e_r the runs' errors.
/// Each run's errors are e_r = T_r f_r with T_r = WhiteNoiseCovariance^(1/2), the shape they
/// would have under white noise (B0's error included), and the whitened f_r share one covariance
/// C (3 x 3) across runs: sigma² I under white noise, some other C when slow noise such as
/// bias instability moves the runs. The whitened residuals T_r^-1 r_r = (I - V W^T) f with
/// V_r = T_r^-1 U_r, W_r = T_r U_r.
struct RunScatter {
  Eigen::MatrixXd V, W;           ///< 3m x 9, runs stacked
  Eigen::Matrix<double, 9, 9> L;  ///< E[vec sum_r f~_r f~_r^T] = L vec(C) (the moment equations)
  Eigen::Matrix3d C;              ///< the unbiased moment estimate, clipped to be positive semi-definite
};

RunScatter EstimateRunScatter(const std::vector<ReducedRun>& data, const Eigen::MatrixXd& U,
                              const Eigen::VectorXd& residual) {
  const auto m = static_cast<Eigen::Index>(data.size());
  RunScatter rs;
  rs.V.resize(3 * m, 9);
  rs.W.resize(3 * m, 9);
  Eigen::Matrix3d M = Eigen::Matrix3d::Zero();
  for (Eigen::Index r = 0; r < m; ++r) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(WhiteNoiseCovariance(data[static_cast<size_t>(r)]));
    const Eigen::Vector3d lambda = eig.eigenvalues().cwiseMax(1e-12 * eig.eigenvalues().maxCoeff());
    const Eigen::Matrix3d T = eig.eigenvectors() * lambda.cwiseSqrt().asDiagonal() * eig.eigenvectors().transpose();
    const Eigen::Matrix3d Tinv =
        eig.eigenvectors() * lambda.cwiseSqrt().cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
    rs.V.middleRows<3>(3 * r).noalias() = Tinv * U.middleRows<3>(3 * r);
    rs.W.middleRows<3>(3 * r).noalias() = T * U.middleRows<3>(3 * r);
    const Eigen::Vector3d f = Tinv * residual.segment<3>(3 * r);
    M.noalias() += f * f.transpose();
  }
  // sum_{r,s} K_rs (x) K_rs with K_rs = delta_rs I - V_r W_s^T, as E[M(i,j)] = sum K(i,k) C(k,l) K(j,l):
  // m I - sum_r (delta_ik X_rr(j,l) + X_rr(i,k) delta_jl) + T_V T_W^T, X_rr = V_r W_r^T,
  // T_V(i + 3j, a + 9b) = sum_r V_r(i,a) V_r(j,b): O(runs), no 3m x 3m matrix.
  rs.L = static_cast<double>(m) * Eigen::Matrix<double, 9, 9>::Identity();
  Eigen::Matrix<double, 9, 81> TV = Eigen::Matrix<double, 9, 81>::Zero(), TW = TV;
  for (Eigen::Index r = 0; r < m; ++r) {
    const Eigen::Matrix<double, 3, 9> Vr = rs.V.middleRows<3>(3 * r), Wr = rs.W.middleRows<3>(3 * r);
    const Eigen::Matrix3d X = Vr * Wr.transpose();
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        for (int k = 0; k < 3; ++k)
          for (int l = 0; l < 3; ++l) rs.L(i + 3 * j, k + 3 * l) -= (i == k ? X(j, l) : 0.0) + (j == l ? X(i, k) : 0.0);
        for (int a = 0; a < 9; ++a)
          for (int b = 0; b < 9; ++b) {
            TV(i + 3 * j, a + 9 * b) += Vr(i, a) * Vr(j, b);
            TW(i + 3 * j, a + 9 * b) += Wr(i, a) * Wr(j, b);
          }
      }
  }
  rs.L.noalias() += TV * TW.transpose();
  const Eigen::Matrix<double, 9, 1> c =
      rs.L.colPivHouseholderQr().solve(Eigen::Map<const Eigen::Matrix<double, 9, 1>>(M.data()));
  const Eigen::Matrix3d C = Eigen::Map<const Eigen::Matrix3d>(c.data());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(0.5 * (C + C.transpose()));
  rs.C = eig.eigenvectors() * eig.eigenvalues().cwiseMax(0.0).asDiagonal() * eig.eigenvectors().transpose();
  return rs;
}

/// Satterthwaite degrees of freedom of one coefficient's run-scatter variance
/// v = tr(C_hat Q), Q = sum_r q_r q_r^T with q_r = W_r g (g its row of G). v = sum_r f~_r^T D f~_r
/// with vec(D) = L^-T vec(Q), a quadratic form in the whitened residuals (I - V W^T) f. With
/// f ~ N(0, I), i.e. at the working model of white noise as Bell and McCaffrey evaluate
/// cluster-robust errors (a plug-in C_hat from 4-6 runs is too rough: it gave dof ~1e-3):
/// (I - V W^T)(I - V W^T)^T = I - Y K Y^T with Y = [V W], K = [[-W^T W, I], [I, 0]], so with
/// G1 = sum_r Y_r^T D Y_r and G2 = sum_r Y_r^T D² Y_r (18 x 18):
///   E[v] = m tr(D) - tr(K G1),   Var[v] / 2 = m tr(D²) - 2 tr(K G2) + tr((K G1)²),
/// and dof = 2 E[v]² / Var[v]. E[v] = tr(Q) checks that the estimate is unbiased.
double ScatterDof(const RunScatter& rs, const Eigen::Matrix3d& Q) {
  const Eigen::Matrix<double, 9, 1> d =
      rs.L.transpose().colPivHouseholderQr().solve(Eigen::Map<const Eigen::Matrix<double, 9, 1>>(Q.data()));
  const Eigen::Matrix3d D0 = Eigen::Map<const Eigen::Matrix3d>(d.data());
  const Eigen::Matrix3d D = 0.5 * (D0 + D0.transpose());
  const Eigen::Matrix3d D2 = D * D;
  const Eigen::Index m = rs.V.rows() / 3;
  Eigen::Matrix<double, 18, 18> G1 = Eigen::Matrix<double, 18, 18>::Zero(), G2 = G1;
  for (Eigen::Index r = 0; r < m; ++r) {
    Eigen::Matrix<double, 3, 18> Y;
    Y << rs.V.middleRows<3>(3 * r), rs.W.middleRows<3>(3 * r);
    G1.noalias() += Y.transpose() * D * Y;
    G2.noalias() += Y.transpose() * D2 * Y;
  }
  Eigen::Matrix<double, 18, 18> K = Eigen::Matrix<double, 18, 18>::Zero();
  K.topLeftCorner<9, 9>() = -(rs.W.transpose() * rs.W);
  K.topRightCorner<9, 9>().setIdentity();
  K.bottomLeftCorner<9, 9>().setIdentity();
  const Eigen::Matrix<double, 18, 18> KG1 = K * G1;
  const auto md = static_cast<double>(m);
  const double mean = md * D.trace() - KG1.trace();
  const double half_var = md * D2.trace() - 2.0 * (K * G2).trace() + (KG1 * KG1).trace();
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

const char* Guo2006MethodName(Guo2006Method method) {
  return method == Guo2006Method::kJoint ? "joint" : "two_stage";
}

std::optional<Guo2006Method> ParseGuo2006Method(std::string_view name) {
  for (const Guo2006Method m : {Guo2006Method::kJoint, Guo2006Method::kTwoStage})
    if (name == Guo2006MethodName(m)) return m;
  return std::nullopt;
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
  const Eigen::Vector3d a = c.RunCoefficients(Ti.front());  // Predict's, constant in the run
  double sse = 0.0;
  for (size_t k = 0; k < run.size(); ++k) {
    const double e = b[k] - B0 - a.dot(Guo2006Features(Ti[k], Tj[k], Ti.front()));
    sse += e * e;
  }
  return sse;
}

namespace {

/// The joint fit: all nine A_kl in one least squares over the runs' reduced rows, with their
/// run-scatter or within-run white-noise errors (the header's Standard errors). Sets c.A and
/// c.A_stderr (c.stderr_dof too for run scatter); returns the scaled condition number.
double FitJoint(const std::vector<ReducedRun>& data, const FitOptions& o, const std::string& hint, bool run_scatter,
                double var_white, Guo2006Coefficients& c) {
  const std::vector<std::string> names9(std::begin(kCoefficientNames), std::end(kCoefficientNames));
  const auto m = static_cast<Eigen::Index>(data.size());
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
  // beta - beta_true = G U^T e with U = S G, e_r the runs' errors of covariance C_r:
  // Cov = G (sum_r U_r^T C_r U_r) G^T; var(A_j) = sum_r u_r^T C_r u_r, u_r = U_r (row j of G)^T.
  const Eigen::MatrixXd U = S * ls.G;
  if (run_scatter) {
    // C_r = T_r C T_r: var(A_j) = sum_r q_r^T C q_r = tr(C Q), q_r = W_r g.
    const RunScatter rs = EstimateRunScatter(data, U, z - S * ls.beta);
    for (int j = 0; j < 9; ++j) {
      const Eigen::Matrix<double, 9, 1> g = ls.G.row(j).transpose();
      Eigen::Matrix3d Q = Eigen::Matrix3d::Zero();
      for (Eigen::Index r = 0; r < m; ++r) {
        const Eigen::Vector3d q = rs.W.middleRows<3>(3 * r) * g;
        Q.noalias() += q * q.transpose();
      }
      c.A_stderr(j / 3, j % 3) = std::sqrt((rs.C * Q).trace());
      c.stderr_dof(j / 3, j % 3) = ScatterDof(rs, Q);
    }
  } else {
    for (int j = 0; j < 9; ++j) {
      const Eigen::Matrix<double, 9, 1> g = ls.G.row(j).transpose();
      double var = 0.0;
      for (Eigen::Index r = 0; r < m; ++r) {
        const Eigen::Vector3d u = U.middleRows<3>(3 * r) * g;
        var += var_white * u.dot(WhiteNoiseCovariance(data[static_cast<size_t>(r)]) * u);
      }
      c.A_stderr(j / 3, j % 3) = std::sqrt(var);
    }
  }
  return ls.cond;
}

/// The two-stage fit: per run a_k by least squares, then for each k a quadratic in Ti0 across
/// runs, with the errors of the header's Standard errors. Sets c.A and c.A_stderr; returns the
/// largest scaled condition number of the fits.
double FitTwoStage(const std::vector<const sim::Run*>& runs, const std::vector<ReducedRun>& data, const FitOptions& o,
                   const std::string& hint, bool run_scatter, double var_white, Guo2006Coefficients& c) {
  const auto m = static_cast<Eigen::Index>(data.size());
  const std::vector<std::string> names3 = {"a1", "a2", "a3"};
  Eigen::MatrixXd a(m, 3), W(m, 3);
  std::vector<Eigen::Matrix3d> run_cov(data.size());  // of each run's a_k, for three runs
  double cond = 0.0;
  for (Eigen::Index r = 0; r < m; ++r) {
    const ReducedRun& d = data[static_cast<size_t>(r)];
    const LsResult lr = SolveLeastSquares(
        d.R3, d.z, names3, o.max_condition_number,
        fmt::format("{}: the temperatures must change during the run", runs[static_cast<size_t>(r)]->Where()));
    a.row(r) = lr.beta.transpose();
    if (!run_scatter) {
      // a_r - a = R3^-1 e_r: Cov = R3^-1 C_r R3^-T.
      const Eigen::Matrix3d R3inv = d.R3.triangularView<Eigen::Upper>().solve(Eigen::Matrix3d::Identity());
      run_cov[static_cast<size_t>(r)] = var_white * R3inv * WhiteNoiseCovariance(d) * R3inv.transpose();
    }
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
        var += P.col(r).cwiseAbs2() * run_cov[static_cast<size_t>(r)](k, k);
      c.A_stderr.row(k) = var.cwiseSqrt().transpose();
    }
    cond = std::max(cond, lr.cond);
  }
  return cond;
}

}  // namespace

Guo2006Coefficients FitGuo2006(const std::vector<const sim::Run*>& runs, const FitOptions& o) {
  if (runs.empty()) throw InputError("fit: no runs selected");
  std::vector<ReducedRun> data;
  std::vector<double> t0s;
  Guo2006Coefficients c;
  c.pair = o.pair;
  c.b0_window_s = o.b0_window_s;
  c.t10_range_C = {INFINITY, -INFINITY};
  double n = 0.0;
  for (const sim::Run* r : runs) {
    data.push_back(Reduce(*r, o));
    n += data.back().n;
    t0s.push_back(data.back().Ti0);
    c.runs.push_back(r->id);
    c.t10_range_C[0] = std::min(c.t10_range_C[0], data.back().Ti0);
    c.t10_range_C[1] = std::max(c.t10_range_C[1], data.back().Ti0);
  }
  const std::vector<StartTemperature> groups = StartTemperatures(runs, t0s);
  if (groups.size() < 3) throw NumericalError(TooFewStartTemperatures(groups, runs.size()));
  const std::string hint = IdentifiabilityHint(groups.size());
  const auto m = static_cast<Eigen::Index>(data.size());
  // Three runs leave no scatter about the fit: the errors then come from the within-run noise,
  // taken white, with B0's error (WhiteNoiseCovariance); its variance has n - 3m dof.
  const bool run_scatter = m > 3;
  const double var_white = run_scatter ? 0.0 : WhiteNoiseVariance(data);
  c.stderr_method = run_scatter ? "run_scatter" : "within_run_white";
  c.stderr_dof.setConstant(run_scatter ? static_cast<double>(m - 3) : n - 3.0 * static_cast<double>(m));

  auto finish = [&](double cond) {
    c.condition_number = cond;
    double ssr = 0.0;  // Eq. (3) with the paper's B0 over every sample
    for (const sim::Run* r : runs) ssr += RunSse(c, *r);
    c.residual_rms_dph = std::sqrt(ssr / n);
    return c;
  };

  c.method = o.method;
  if (o.method == Guo2006Method::kJoint) return finish(FitJoint(data, o, hint, run_scatter, var_white, c));
  return finish(FitTwoStage(runs, data, o, hint, run_scatter, var_white, c));
}

}  // namespace rlg::model
