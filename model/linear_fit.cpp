#include "model/linear_fit.h"

#include <algorithm>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <memory>

#include "sim/errors.h"

namespace rlg::model {

Design BuildDesign(const std::vector<const sim::Run*>& runs, const CausalRegressors& regressors, const RowMask& mask,
                   const std::string& bias_column) {
  Design d;
  d.names = regressors.names();
  d.offset = regressors.offset();
  const auto p = static_cast<Eigen::Index>(d.names.size());
  const std::vector<std::string>& channels = regressors.channels();
  size_t n = 0;
  for (size_t r = 0; r < runs.size(); ++r) {
    const sim::Run& run = *runs[r];
    for (const auto& ch : channels) {
      if (!run.Has(ch)) {
        throw InputError(fmt::format("{} has no temperature channel '{}' (columns: {})", run.Where(), ch,
                                     fmt::join(run.names, ",")));
      }
    }
    run.Column(bias_column);  // refuses a run without it, naming the run
    if (mask.empty()) {
      n += run.size();
    } else {
      n += static_cast<size_t>(std::count_if(mask[r].begin(), mask[r].end(), [](char c) { return c != 0; }));
    }
  }
  d.X.resize(static_cast<Eigen::Index>(n), p);
  d.y.resize(static_cast<Eigen::Index>(n));
  d.run.reserve(n);
  d.in_b0_window.reserve(n);
  const bool power_on = d.offset == OffsetRule::kPowerOn;
  const bool referred = regressors.ReferredToB0Window();
  const double window = regressors.b0_window_s();
  std::unique_ptr<CausalRegressors> g = regressors.Clone();
  std::vector<const std::vector<double>*> T(channels.size());
  std::vector<double> temperatures(channels.size());
  // Row-major: Next writes one sample's regressors contiguously.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows;
  Eigen::Index at = 0;
  for (size_t r = 0; r < runs.size(); ++r) {
    const sim::Run& run = *runs[r];
    if (run.size() == 0) continue;
    for (size_t c = 0; c < channels.size(); ++c) T[c] = &run.Column(channels[c]);
    const std::vector<double>& bias = run.Column(bias_column);
    const double t_end = run.t_s.front() + window;
    if (power_on && run.t_s.back() < t_end) {
      throw InputError(fmt::format("{} lasts {:g} s, shorter than the {:g} s B0 window the model needs", run.Where(),
                                   run.t_s.back() - run.t_s.front(), window));
    }
    // Every sample's regressors from power-on, then the run's references: B0 (and G0, the
    // regressors' mean over the same window samples) from every window sample, used or not.
    rows.resize(static_cast<Eigen::Index>(run.size()), p);
    g->Reset();
    for (size_t k = 0; k < run.size(); ++k) {
      for (size_t c = 0; c < channels.size(); ++c) temperatures[c] = (*T[c])[k];
      g->Next(run.t_s[k], temperatures.data(), rows.row(static_cast<Eigen::Index>(k)).data());
    }
    double B0 = 0.0;
    Eigen::RowVectorXd G0 = Eigen::RowVectorXd::Zero(p);
    if (power_on) {
      size_t count = 0;
      for (size_t k = 0; k < run.size() && run.t_s[k] < t_end; ++k, ++count) {
        B0 += bias[k];
        G0 += rows.row(static_cast<Eigen::Index>(k));
      }
      B0 /= static_cast<double>(count);
      G0 /= static_cast<double>(count);
      if (!referred) G0.setZero();
    }
    for (size_t k = 0; k < run.size(); ++k) {
      if (!mask.empty() && !mask[r][k]) continue;
      d.X.row(at) = rows.row(static_cast<Eigen::Index>(k)) - G0;
      d.y[at] = bias[k] - B0;
      d.run.push_back(static_cast<int>(r));
      d.in_b0_window.push_back(power_on && run.t_s[k] < t_end ? 1 : 0);
      ++at;
    }
  }
  return d;
}

bool LinearFitOptions::IsValid(std::string* error) const {
  std::string why;
  if (!(max_condition_number > 1.0)) why = fmt::format("max_condition_number must exceed 1 (got {:g})", max_condition_number);
  else if (min_blocks < 2 || blocks < min_blocks)
    why = fmt::format("blocks must be at least min_blocks, and min_blocks at least 2 (got {} and {})", blocks, min_blocks);
  else if (min_runs_as_clusters < 2) why = fmt::format("min_runs_as_clusters must be at least 2 (got {})", min_runs_as_clusters);
  if (error) *error = why;
  return why.empty();
}

double StudentQuantile(double level, double dof) {
  if (!(level > 0.0 && level < 1.0)) throw InputError(fmt::format("confidence level {:g}: expected 0 < level < 1", level));
  if (!(dof > 0.0)) throw InputError("an interval needs positive degrees of freedom (coefficients read from a file carry none)");
  return boost::math::quantile(boost::math::students_t(dof), 0.5 * (1.0 + level));
}

namespace {

/// Each row's cluster: the runs, or contiguous blocks of each run (see the header).
std::vector<int> Clusters(const Design& d, const LinearFitOptions& o, const Eigen::VectorXd& eps, int& count,
                          std::string& method) {
  const size_t n = d.run.size();
  std::vector<size_t> rows_of_run;
  std::vector<int> run_ids;  // the runs present, in order
  for (size_t i = 0; i < n; ++i) {
    if (run_ids.empty() || run_ids.back() != d.run[i]) {
      run_ids.push_back(d.run[i]);
      rows_of_run.push_back(0);
    }
    ++rows_of_run.back();
  }
  const size_t m = run_ids.size();
  std::vector<int> cluster(n);
  if (static_cast<int>(m) >= o.min_runs_as_clusters) {
    method = "cluster_runs";
    count = static_cast<int>(m);
    size_t at = 0;
    for (size_t r = 0; r < m; ++r)
      for (size_t k = 0; k < rows_of_run[r]; ++k) cluster[at++] = static_cast<int>(r);
    return cluster;
  }
  method = "cluster_blocks";
  // Blocks of at least ten integrated correlation times of the noise estimates, (1 + rho) /
  // (1 - rho) samples with rho their lag-1 autocorrelation within runs: from min_blocks to
  // `blocks` of them, and two rows a block at least; shared among the runs in proportion to
  // their rows (largest remainders), one at least per run.
  double c0 = 0.0, c1 = 0.0;
  for (size_t i = 0; i < n; ++i) {
    c0 += eps[static_cast<Eigen::Index>(i)] * eps[static_cast<Eigen::Index>(i)];
    if (i > 0 && d.run[i] == d.run[i - 1]) c1 += eps[static_cast<Eigen::Index>(i)] * eps[static_cast<Eigen::Index>(i - 1)];
  }
  const double rho = std::clamp(c0 > 0.0 ? c1 / c0 : 0.0, 0.0, 0.999);
  const double correlation = (1.0 + rho) / (1.0 - rho);
  const auto wanted = static_cast<size_t>(std::floor(static_cast<double>(n) / (10.0 * correlation)));
  const size_t by_noise = std::clamp<size_t>(wanted, static_cast<size_t>(o.min_blocks), static_cast<size_t>(o.blocks));
  const size_t total = std::max<size_t>(m, std::min<size_t>(by_noise, n / 2));
  std::vector<size_t> blocks(m, 1);
  size_t given = m;
  std::vector<std::pair<double, size_t>> remainders;
  for (size_t r = 0; r < m; ++r) {
    const double share = static_cast<double>(total) * static_cast<double>(rows_of_run[r]) / static_cast<double>(n);
    const size_t whole = std::max<size_t>(1, static_cast<size_t>(std::floor(share)));
    given += whole - 1;
    blocks[r] = whole;
    remainders.emplace_back(share - std::floor(share), r);
  }
  std::sort(remainders.begin(), remainders.end(), std::greater<>());
  for (size_t k = 0; given < total && k < remainders.size(); ++k, ++given) ++blocks[remainders[k].second];
  size_t at = 0;
  int next = 0;
  for (size_t r = 0; r < m; ++r) {
    const size_t b = std::min(blocks[r], std::max<size_t>(1, rows_of_run[r]));
    for (size_t k = 0; k < rows_of_run[r]; ++k) cluster[at++] = next + static_cast<int>(k * b / rows_of_run[r]);
    next += static_cast<int>(b);
  }
  count = next;
  return cluster;
}

/// o.hint's text for the coefficients named, or nothing without a hint.
std::string Hint(const LinearFitOptions& o, const std::vector<std::string>& involved) {
  return o.hint ? o.hint(involved) : std::string();
}

/// Each regressor's Euclidean norm over the samples, the scale of its coefficient; refuses too few
/// samples for the coefficients and the noise, and a regressor that is zero in every sample.
Eigen::VectorXd ColumnScale(const Design& d, const LinearFitOptions& o) {
  const Eigen::Index n = d.X.rows(), p = d.X.cols();
  if (n <= p) {
    throw NumericalError(fmt::format("{} samples cannot determine {} coefficients and the noise{}", n, p,
                                     o.hint ? ": " + Hint(o, d.names) : std::string()));
  }
  Eigen::VectorXd scale = d.X.colwise().norm().transpose();
  for (Eigen::Index j = 0; j < p; ++j) {
    if (!(scale[j] > 0.0)) {
      const std::string name = d.names[static_cast<size_t>(j)];
      throw NumericalError(fmt::format("coefficient {} multiplies a regressor that is zero in every sample{}", name,
                                       o.hint ? ": " + Hint(o, {name}) : std::string()));
    }
  }
  return scale;
}

/// The scaled design's condition number, the largest over the smallest singular value of R;
/// refuses one not below max_condition_number, naming the coefficients the data cannot separate.
double CheckedConditionNumber(const Design& d, const LinearFitOptions& o, const Eigen::MatrixXd& R) {
  const Eigen::Index p = d.X.cols();
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(R, Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  const double cond = sv[0] / sv[p - 1];
  if (!(cond < o.max_condition_number)) {
    // The right singular vectors of the (near-)zero singular values span what the data cannot
    // see: name every coefficient that takes part in them.
    std::vector<std::string> involved;
    for (Eigen::Index j = 0; j < p; ++j) {
      bool in_null_space = false;
      for (Eigen::Index s = 0; s < p; ++s) {
        if (sv[s] * o.max_condition_number < sv[0] && std::abs(svd.matrixV()(j, s)) > 0.2) in_null_space = true;
      }
      if (in_null_space) involved.push_back(d.names[static_cast<size_t>(j)]);
    }
    throw NumericalError(fmt::format("ill-conditioned fit (scaled condition number {:.3g}): the data cannot separate "
                                     "coefficients {}{}",
                                     cond, fmt::join(involved, ", "), o.hint ? "; " + Hint(o, involved) : std::string()));
  }
  return cond;
}

/// (R^T R)^-1 a, R upper triangular: two triangular solves.
Eigen::VectorXd InverseGram(const Eigen::MatrixXd& R, const Eigen::VectorXd& a) {
  const auto upper = R.triangularView<Eigen::Upper>();
  return upper.solve(upper.transpose().solve(a));
}

/// The noise estimates and B0's share of the coefficients' variance (scaled units²) with its
/// degrees of freedom.
struct NoiseEstimates {
  Eigen::VectorXd eps;
  Eigen::VectorXd b0_part;
  double b0_dof = 0.0;
};

/// B0's share of the scaled coefficients' variance from one run's rows [begin, begin + rows) with
/// `window` of them in its B0 window, added to b0_part and b0_dof.
void AddRunB0Part(const Eigen::MatrixXd& Xs, const Eigen::MatrixXd& R, const Eigen::VectorXd& eps, Eigen::Index begin,
                  Eigen::Index rows, Eigen::Index window, NoiseEstimates& noise) {
  // B0 is a window-long mean of the noise: its variance is that of the means of
  // consecutive window-long batches of the run's noise estimates (batch means: they carry
  // the noise's correlation up to the window's length); one batch alone: white noise.
  const Eigen::Index batches = rows / window;
  double variance = 0.0, dof = 0.0;
  if (batches >= 2) {
    Eigen::VectorXd means(batches);
    for (Eigen::Index k = 0; k < batches; ++k) means[k] = eps.segment(begin + k * window, window).mean();
    variance = (means.array() - means.mean()).square().sum() / static_cast<double>(batches - 1);
    dof = static_cast<double>(batches - 1);
  } else {
    variance = eps.segment(begin, rows).squaredNorm() / static_cast<double>(rows - 1) / static_cast<double>(window);
    dof = static_cast<double>(rows - 1);
  }
  const Eigen::VectorXd a = InverseGram(R, Xs.middleRows(begin, rows).colwise().sum().transpose());
  noise.b0_part += variance * a.cwiseProduct(a);
  noise.b0_dof += dof;
}

/// The noise estimates (deg/h) and, with a power-on offset, B0's part of the variance.
NoiseEstimates EstimateNoise(const Design& d, const Eigen::MatrixXd& Xs, const Eigen::MatrixXd& R,
                             const Eigen::VectorXd& residual) {
  // The noise estimates: the residuals; with a power-on offset those of the fit with a free
  // constant per run besides (the noise about each run's turn-on bias: B0's own error, a constant
  // over the run that the polynomial partly takes up, must not show in them, or the batch
  // means below grow with the very error they estimate). Per run then: beta's error from B0's,
  // -(X^T X)^-1 S e_B0 (S the sum of the run's regressors), with the variance of e_B0 by batch
  // means.
  const Eigen::Index n = d.X.rows(), p = d.X.cols();
  NoiseEstimates noise;
  noise.eps = residual;
  noise.b0_part = Eigen::VectorXd::Zero(p);
  if (d.offset != OffsetRule::kPowerOn) return noise;
  std::vector<Eigen::Index> starts{0};
  for (Eigen::Index i = 1; i < n; ++i)
    if (d.run[static_cast<size_t>(i)] != d.run[static_cast<size_t>(i - 1)]) starts.push_back(i);
  const auto m = static_cast<Eigen::Index>(starts.size());
  Eigen::MatrixXd Xa(n, p + m);
  Xa << Xs, Eigen::MatrixXd::Zero(n, m);
  for (Eigen::Index r = 0; r < m; ++r) {
    const Eigen::Index end = r + 1 < m ? starts[static_cast<size_t>(r + 1)] : n;
    Xa.block(starts[static_cast<size_t>(r)], p + r, end - starts[static_cast<size_t>(r)], 1).setConstant(1.0);
  }
  noise.eps = d.y - Xa * Eigen::HouseholderQR<Eigen::MatrixXd>(Xa).solve(d.y);
  Eigen::Index begin = 0;
  while (begin < n) {
    Eigen::Index end = begin;
    while (end < n && d.run[static_cast<size_t>(end)] == d.run[static_cast<size_t>(begin)]) ++end;
    const Eigen::Index rows = end - begin;
    Eigen::Index window = 0;
    for (Eigen::Index i = begin; i < end; ++i) window += d.in_b0_window[static_cast<size_t>(i)] ? 1 : 0;
    if (window > 0) AddRunB0Part(Xs, R, noise.eps, begin, rows, window, noise);
    begin = end;
  }
  return noise;
}

/// CR2's pieces: each cluster's rows, U = Xs R^-1, each cluster's scaled coefficient error
/// (column g of a) and its p x p scaling matrix.
struct Cr2 {
  std::vector<std::vector<Eigen::Index>> members;
  Eigen::MatrixXd U;
  Eigen::MatrixXd a;
  std::vector<Eigen::MatrixXd> adjust;
};

/// Each cluster's CR2-adjusted contribution to the scaled coefficients' error.
Cr2 ClusterContributions(const Eigen::MatrixXd& Xs, const Eigen::MatrixXd& R, const std::vector<int>& cluster,
                         int clusters, const Eigen::VectorXd& eps) {
  // CR2: each cluster's residuals scaled by (I - H_gg)^-1/2, H_gg its block of the hat matrix
  // X (X^T X)^-1 X^T = U U^T with U = Xs R^-1. With U_g^T U_g = W diag(l) W^T,
  // (I - U_g U_g^T)^-1/2 e = e + U_g W diag(((1 - l)^-1/2 - 1) / l) W^T U_g^T e: p x p work.
  const Eigen::Index n = Xs.rows(), p = Xs.cols();
  const Eigen::MatrixXd& Z = Xs;
  const auto upper = R.triangularView<Eigen::Upper>();
  Cr2 c;
  c.U = upper.transpose().solve(Xs.transpose()).transpose();  // n x p, Xs R^-1
  c.members.resize(static_cast<size_t>(clusters));
  for (Eigen::Index i = 0; i < n; ++i) c.members[static_cast<size_t>(cluster[static_cast<size_t>(i)])].push_back(i);
  c.a.resize(p, clusters);
  c.adjust.resize(static_cast<size_t>(clusters));
  for (int g = 0; g < clusters; ++g) {
    const auto& rows = c.members[static_cast<size_t>(g)];
    const auto ng = static_cast<Eigen::Index>(rows.size());
    Eigen::MatrixXd Ug(ng, p), Zg(ng, p);
    Eigen::VectorXd eg(ng);
    for (Eigen::Index k = 0; k < ng; ++k) {
      Ug.row(k) = c.U.row(rows[static_cast<size_t>(k)]);
      Zg.row(k) = Z.row(rows[static_cast<size_t>(k)]);
      eg[k] = eps[rows[static_cast<size_t>(k)]];
    }
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(Ug.transpose() * Ug);
    Eigen::VectorXd factor(p);
    for (Eigen::Index j = 0; j < p; ++j) {
      // A cluster that alone fixes a direction (l -> 1) is capped at a 100-fold scale.
      const double l = std::clamp(eig.eigenvalues()[j], 0.0, 1.0 - 1e-4);
      factor[j] = l > 1e-12 ? (1.0 / std::sqrt(1.0 - l) - 1.0) / l : 0.5;
    }
    const Eigen::MatrixXd M = eig.eigenvectors() * factor.asDiagonal() * eig.eigenvectors().transpose();
    const Eigen::VectorXd adjusted = eg + Ug * (M * (Ug.transpose() * eg));
    c.a.col(g) = InverseGram(R, Zg.transpose() * adjusted);
    c.adjust[static_cast<size_t>(g)] = M;
  }
  return c;
}

/// Column g of Gm for coefficient direction w: (I - H) D P_g^T a_g (see BellMcCaffreyDof).
Eigen::VectorXd DofColumn(const Design& d, const Cr2& c, const Eigen::MatrixXd& Zr, const Eigen::VectorXd& w, int g,
                          bool demean) {
  const Eigen::Index n = d.X.rows(), p = d.X.cols();
  const auto& rows = c.members[static_cast<size_t>(g)];
  const auto ng = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd Ug(ng, p);
  Eigen::VectorXd v(ng);
  for (Eigen::Index k = 0; k < ng; ++k) {
    Ug.row(k) = c.U.row(rows[static_cast<size_t>(k)]);
    v[k] = Zr.row(rows[static_cast<size_t>(k)]).dot(w);
  }
  v += Ug * (c.adjust[static_cast<size_t>(g)] * (Ug.transpose() * v));
  Eigen::VectorXd col = Eigen::VectorXd::Zero(n);
  for (Eigen::Index k = 0; k < ng; ++k) col[rows[static_cast<size_t>(k)]] = v[k];
  if (demean) {
    Eigen::Index begin = 0;
    while (begin < n) {
      Eigen::Index end = begin;
      while (end < n && d.run[static_cast<size_t>(end)] == d.run[static_cast<size_t>(begin)]) ++end;
      col.segment(begin, end - begin).array() -= col.segment(begin, end - begin).mean();
      begin = end;
    }
  }
  return col - c.U * (c.U.transpose() * col);
}

/// Each coefficient's Student's t degrees of freedom: Bell-McCaffrey's for the cluster part,
/// with B0's part combined by Satterthwaite.
Eigen::VectorXd BellMcCaffreyDof(const Design& d, const Eigen::MatrixXd& Xs, const Eigen::MatrixXd& R, const Cr2& c,
                                 int clusters, const Eigen::VectorXd& cluster_part, const NoiseEstimates& noise) {
  // Bell-McCaffrey degrees of freedom per coefficient, at white noise: the variance estimate
  // is sum_g (a_g^T eps_g)² with a_g = A_g Z_g (X^T X)^-1 e_j (A_g the CR2 scaling) and
  // eps = D (I - H) e (D: minus the run means for a power-on offset, else I), a quadratic form
  // e^T K~ e whose dof is (tr K)² / tr(K²), K = Gm^T Gm, Gm's column g = (I - H) D P_g^T a_g.
  // Below G - 1 when a coefficient rests on a few clusters: a polynomial's highest power on the
  // blocks at the ends of the temperature range, a power-on model's on the block holding B0.
  const Eigen::Index n = d.X.rows(), p = d.X.cols();
  const double G = clusters;
  const bool demean = d.offset == OffsetRule::kPowerOn;
  const Eigen::MatrixXd& Z = Xs;
  const auto upper = R.triangularView<Eigen::Upper>();
  Eigen::VectorXd dof_per_coefficient(p);
  Eigen::MatrixXd Gm(n, clusters);
  const Eigen::MatrixXd Zr = upper.transpose().solve(Z.transpose()).transpose();  // Z R^-1
  for (Eigen::Index j = 0; j < p; ++j) {
    const Eigen::VectorXd w = upper.transpose().solve(Eigen::VectorXd::Unit(p, j));
    Gm.setZero();
    for (int g = 0; g < clusters; ++g) Gm.col(g) = DofColumn(d, c, Zr, w, g, demean);
    const Eigen::MatrixXd K = Gm.transpose() * Gm;
    const double trace = K.trace(), trace2 = K.squaredNorm();
    const double dof_cluster = trace2 > 0.0 ? std::clamp(trace * trace / trace2, 1.0, G - 1.0) : G - 1.0;
    // With B0's part, Satterthwaite's combination of the two variance estimates.
    const double vc = cluster_part[j], vb = noise.b0_part[j], b0_dof = noise.b0_dof;
    dof_per_coefficient[j] = vb > 0.0 && b0_dof > 0.0
                                 ? std::clamp((vc + vb) * (vc + vb) / (vc * vc / dof_cluster + vb * vb / b0_dof), 1.0,
                                              dof_cluster + b0_dof)
                                 : dof_cluster;
  }
  return dof_per_coefficient;
}

}  // namespace

LinearFit FitLinear(const Design& d, const LinearFitOptions& o) {
  std::string invalid;
  if (!o.IsValid(&invalid)) throw InputError("linear fit options: " + invalid);
  const Eigen::Index n = d.X.rows(), p = d.X.cols();
  const Eigen::VectorXd scale = ColumnScale(d, o);
  const Eigen::MatrixXd Xs = d.X * scale.cwiseInverse().asDiagonal();
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(Xs);
  const Eigen::MatrixXd R = qr.matrixQR().topRows(p).triangularView<Eigen::Upper>();
  const double cond = CheckedConditionNumber(d, o, R);
  LinearFit f;
  f.condition_number = cond;
  f.n = static_cast<size_t>(n);
  const Eigen::VectorXd beta_s = qr.solve(d.y);
  f.beta = beta_s.cwiseQuotient(scale);
  const Eigen::VectorXd residual = d.y - d.X * f.beta;
  f.rss = residual.squaredNorm();
  f.residual_rms_dph = std::sqrt(f.rss / static_cast<double>(n));
  if (!o.errors) return f;

  // The white-noise formula, for comparison.
  {
    const double sigma2 = f.rss / static_cast<double>(n - p);
    Eigen::VectorXd v(p);
    for (Eigen::Index j = 0; j < p; ++j) v[j] = InverseGram(R, Eigen::VectorXd::Unit(p, j))[j];
    f.white_standard_error = (sigma2 * v).cwiseSqrt().cwiseQuotient(scale);
  }
  const NoiseEstimates noise = EstimateNoise(d, Xs, R, residual);
  const std::vector<int> cluster = Clusters(d, o, noise.eps, f.clusters, f.stderr_method);
  const Cr2 c = ClusterContributions(Xs, R, cluster, f.clusters, noise.eps);
  const double G = f.clusters;
  const Eigen::VectorXd cluster_part = c.a.rowwise().squaredNorm();
  f.standard_error = (cluster_part + noise.b0_part).cwiseSqrt().cwiseQuotient(scale);
  f.dof_per_coefficient = BellMcCaffreyDof(d, Xs, R, c, f.clusters, cluster_part, noise);
  f.dof = G - 1.0;
  return f;
}

}  // namespace rlg::model
