#include "diagnosis/data/prepare.h"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <limits>

#include <Eigen/Sparse>

#include "model/allan.h"
#include "sim/errors.h"

namespace rlg::diagnosis {

using sim::Profile;

void BlockLayout(PreparedRun& p, const DiagnoseOptions& o) {
  p.sample_period_s = model::SamplePeriod(p.run->t_s);  // the median step: robust to a gap or jitter
  p.fit_block_s = p.sample_period_s * std::max(1.0, std::round(o.fit_block_s / p.sample_period_s));
  p.fit_blocks_per_score = static_cast<int>(std::max(1.0, std::round(o.score_block_s / p.fit_block_s)));
}

std::vector<PreparedRun> Prepare(const sim::Trace& data, const sim::GyroConfig& gyro, const DiagnoseOptions& o) {
  std::vector<PreparedRun> out;
  for (const auto& run : data.runs) {
    PreparedRun p;
    p.run = &run;
    p.label = run.id;
    p.nuisance = static_cast<int>(out.size());
    if (run.size() < 20) throw InputError(fmt::format("{}: {} samples are too few to diagnose", run.Where(), run.size()));
    p.ambient_known = run.Has("T_amb");  // its curve is built with the blocks (MakeProblem)
    for (const auto& src : gyro.network.sources) {
      const std::string col = "P_" + src.name + "_W";
      const int c = run.Find(col);
      p.power_logged.push_back(c >= 0);
      if (c < 0 && src.driven_by_data) {
        throw InputError(fmt::format("{}: source '{}' of the gyro is driven by data but the data has no column '{}'",
                                     run.Where(), src.name, col));
      }
      if (c < 0) {  // the gyro's power_W, constant
        p.data_power.push_back(Profile::Constant(src.power_W));
        continue;
      }
      // Zero-order hold of the logged power, with a breakpoint only where it changes (each one
      // restarts the integrator).
      std::vector<std::pair<double, double>> steps;
      for (size_t k = 1; k < run.size(); ++k)
        if (run.columns[c][k] != run.columns[c][k - 1]) steps.emplace_back(run.t_s[k], run.columns[c][k]);
      p.data_power.push_back(Profile::Steps(run.columns[c][0], steps));
    }
    bool any = false;
    for (const auto& s : gyro.sensors) {
      p.sensor_col.push_back(run.Find(s.channel));
      any = any || p.sensor_col.back() >= 0;
    }
    if (!any) throw InputError(fmt::format("{} has none of the gyro's temperature channels", run.Where()));
    p.bias_col = run.Find("bias_dph");
    BlockLayout(p, o);
    out.push_back(std::move(p));
  }
  return out;
}

SplitRun SplitInTime(const PreparedRun& whole, int pieces) {
  const auto& t = whole.run->t_s;
  pieces = std::max(2, pieces);
  const double len = (t.back() - t.front()) / pieces;
  SplitRun out{whole, whole, {}};
  for (int i = 0; i < pieces; ++i) {
    const double from = t.front() + i * len, to = i + 1 == pieces ? std::numeric_limits<double>::infinity() : from + len;
    (i % 2 ? out.held : out.fit).windows.emplace_back(from, to);
  }
  auto spans = [&](const PreparedRun& p) {
    std::vector<std::string> s;
    for (const auto& w : p.windows) s.push_back(fmt::format("{:.0f}-{:.0f}", w.first, std::min(w.second, t.back())));
    return fmt::format("t = {} s", fmt::join(s, ", "));
  };
  out.fit.label = fmt::format("{} ({})", whole.run->id, spans(out.fit));
  out.held.label = fmt::format("{} ({}, held out)", whole.run->id, spans(out.held));
  out.note = fmt::format("one run, held out in time: fitted on {}, scored on {}", spans(out.fit), spans(out.held));
  out.fit.nuisance = out.held.nuisance = 0;
  return out;
}

std::vector<std::pair<size_t, size_t>> Blocks(const std::vector<double>& t, double block_s, double sample_period_s) {
  std::vector<std::pair<size_t, size_t>> b;
  size_t k = 0;
  while (k < t.size()) {
    size_t e = k + 1;
    while (e < t.size() && t[e] < t[k] + block_s - 5e-7) ++e;
    b.emplace_back(k, e);
    k = e;
  }
  const double full = std::round(block_s / sample_period_s);
  if (b.size() > 1 && 2.0 * static_cast<double>(b.back().second - b.back().first) < full) b.pop_back();
  return b;
}

double BlockMean(const std::vector<double>& v, std::pair<size_t, size_t> b) {
  double s = 0.0;
  for (size_t i = b.first; i < b.second; ++i) s += v[i];
  return s / static_cast<double>(b.second - b.first);
}

double ScoreBlockNoise(const std::vector<PreparedRun>& runs) {
  double noise = std::numeric_limits<double>::infinity();
  for (const auto& p : runs) {
    if (p.run->size() < 3) continue;
    const double per_block = std::round(p.score_block_s() / p.sample_period_s);
    for (int col : p.sensor_col) {
      if (col < 0) continue;
      const auto& v = p.run->columns[col];
      double ss = 0.0;
      for (size_t k = 1; k < v.size(); ++k) ss += (v[k] - v[k - 1]) * (v[k] - v[k - 1]);
      const double sd = std::sqrt(ss / static_cast<double>(v.size() - 1) / 2.0);
      if (sd > 0.0) noise = std::min(noise, sd / std::sqrt(per_block));
    }
  }
  return noise;
}

double PointNoise(const std::vector<std::pair<double, double>>& pts) {
  std::vector<double> d;
  for (size_t i = 1; i + 1 < pts.size(); ++i) {
    const double di = std::abs(pts[i + 1].second - 2.0 * pts[i].second + pts[i - 1].second);
    if (di > 0.0) d.push_back(di);
  }
  if (d.empty()) return 0.0;
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return d[d.size() / 2] / 0.6745 / std::sqrt(6.0);
}

double NoiseAtEveryPoint(const std::vector<std::pair<double, double>>& pts) {
  if (pts.size() < 3) return 0.0;
  double scale = 0.0;
  for (const auto& p : pts) scale = std::max(scale, std::abs(p.second));
  std::vector<double> d;
  for (size_t i = 1; i + 1 < pts.size(); ++i) {
    const double di = std::abs(pts[i + 1].second - 2.0 * pts[i].second + pts[i - 1].second);
    d.push_back(di > 1e-9 * scale ? di : 0.0);
  }
  std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
  return d[d.size() / 2] / 0.6745 / std::sqrt(6.0);
}

namespace {

/// Least-squares values at `knots` (times, increasing, spanning the points) of the continuous
/// piecewise-linear curve through them, fitted to every point: each point is a hat-function
/// combination of its two knots, so the normal equations are tridiagonal (sparse LDLT). `w`:
/// each point's weight, its variance's inverse in units of the unit point variance (empty: 1
/// each). With `first_variance`: the first knot value's variance per unit point variance,
/// [(A'WA)^-1]_00.
std::vector<std::pair<double, double>> FitKnots(const std::vector<std::pair<double, double>>& pts,
                                                const std::vector<double>& knots, const std::vector<double>& w,
                                                double* first_variance = nullptr) {
  const auto m = static_cast<Eigen::Index>(knots.size());
  std::vector<Eigen::Triplet<double>> entries;
  size_t j = 0;
  for (size_t i = 0; i < pts.size(); ++i) {
    while (j + 2 < knots.size() && pts[i].first > knots[j + 1]) ++j;
    const double u = std::clamp((pts[i].first - knots[j]) / (knots[j + 1] - knots[j]), 0.0, 1.0);
    entries.emplace_back(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j), 1.0 - u);
    entries.emplace_back(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j + 1), u);
  }
  Eigen::SparseMatrix<double> A(static_cast<Eigen::Index>(pts.size()), m);
  A.setFromTriplets(entries.begin(), entries.end());
  Eigen::VectorXd v(static_cast<Eigen::Index>(pts.size()));
  for (size_t i = 0; i < pts.size(); ++i) v[static_cast<Eigen::Index>(i)] = pts[i].second;
  if (!w.empty()) {  // rows scaled by sqrt(w): A'WA and A'Wv
    Eigen::VectorXd root(static_cast<Eigen::Index>(pts.size()));
    for (size_t i = 0; i < pts.size(); ++i) root[static_cast<Eigen::Index>(i)] = std::sqrt(w[i]);
    A = root.asDiagonal() * A;
    v = v.cwiseProduct(root);
  }
  const Eigen::SparseMatrix<double> N = A.transpose() * A;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(N);
  // Every knot carries points (knots are points' times), so N is positive definite.
  if (ldlt.info() != Eigen::Success) throw NumericalError("diagnose: the logged ambient's smoothing fit failed");
  const Eigen::VectorXd x = ldlt.solve(A.transpose() * v);
  if (first_variance) *first_variance = ldlt.solve(Eigen::VectorXd::Unit(m, 0))[0];
  std::vector<std::pair<double, double>> out;
  for (Eigen::Index k = 0; k < m; ++k) out.emplace_back(knots[static_cast<size_t>(k)], x[k]);
  return out;
}

}  // namespace

sim::Profile LoggedAmbientCurve(const std::vector<std::pair<double, double>>& pts, double score_block_noise,
                                double* start_sd, double end_weight) {
  // With ends of another weight, the noise, the knots' places and the refinement come from the
  // points between them (a raw end reading ten times a block mean's variance had placed a knot
  // beside itself on 11 % of noise seeds, leaving the start on that reading alone); the ends
  // then take the first and last knots' times, and the fit weighs them by end_weight.
  const bool ends_apart = end_weight != 1.0 && pts.size() >= 5;
  const std::vector<std::pair<double, double>> inner =
      ends_apart ? std::vector<std::pair<double, double>>(pts.begin() + 1, pts.end() - 1) : pts;
  std::vector<double> weight;
  if (ends_apart) {
    weight.assign(pts.size(), 1.0);
    weight.front() = weight.back() = end_weight;
  }
  const double s = NoiseAtEveryPoint(inner);
  if (start_sd) *start_sd = 0.0;
  if (s == 0.0) {
    // Exact between corners: keep the points where the curve moves (see MakeProblem's).
    const bool finite = std::isfinite(score_block_noise);
    const double floor = finite ? 0.1 * score_block_noise : 0.0, cap = finite ? score_block_noise : 0.0;
    return Profile::Table(sim::SimplifyPolyline(pts, std::max(floor, std::min(3.0 * PointNoise(pts), cap))));
  }
  std::vector<double> knots;
  for (const auto& p : sim::SimplifyPolyline(inner, 5.0 * s)) knots.push_back(p.first);
  if (ends_apart) {
    knots.front() = pts.front().first;
    knots.back() = pts.back().first;
  }
  double first_variance = 0.0;
  std::vector<std::pair<double, double>> curve = FitKnots(pts, knots, weight, &first_variance);
  for (int pass = 0; pass < 50; ++pass) {
    const Profile fitted = Profile::Table(curve);
    std::vector<double> resid(inner.size());
    for (size_t i = 0; i < inner.size(); ++i) resid[i] = inner[i].second - fitted.Value(inner[i].first);
    std::vector<double> added;
    for (size_t w : {8, 32, 128, 512}) {
      for (size_t from = 0; from + w <= inner.size(); from += w) {
        double sum = 0.0;
        for (size_t i = from; i < from + w; ++i) sum += resid[i];
        if (std::abs(sum / static_cast<double>(w)) > 4.0 * s / std::sqrt(static_cast<double>(w)))
          added.push_back(inner[from + w / 2].first);
      }
    }
    const size_t before = knots.size();
    knots.insert(knots.end(), added.begin(), added.end());
    std::sort(knots.begin(), knots.end());
    knots.erase(std::unique(knots.begin(), knots.end()), knots.end());
    if (knots.size() == before) break;
    curve = FitKnots(pts, knots, weight, &first_variance);
  }
  if (start_sd) *start_sd = s * std::sqrt(first_variance);
  return Profile::Table(curve);
}

std::vector<size_t> InputJumps(const std::vector<double>& v, double min_jump) {
  std::vector<size_t> out;
  if (v.size() < 2) return out;
  std::vector<std::pair<double, double>> pts;
  for (size_t i = 0; i < v.size(); ++i) pts.emplace_back(static_cast<double>(i), v[i]);
  const double noise = v.size() >= 3 ? std::sqrt(2.0) * NoiseAtEveryPoint(pts) : 0.0;
  for (size_t k = 1; k < v.size(); ++k) {
    const double d = std::abs(v[k] - v[k - 1]);
    const double before = k >= 2 ? std::abs(v[k - 1] - v[k - 2]) : 0.0;
    const double after = k + 1 < v.size() ? std::abs(v[k + 1] - v[k]) : 0.0;
    if (d > 10.0 * std::max({before, after, noise}) && d > min_jump) out.push_back(k);
  }
  return out;
}

sim::Profile LoggedAmbient(const std::vector<double>& t, const std::vector<double>& v, double sample_period_s,
                           double score_block_noise, double* start_sd) {
  if (start_sd) *start_sd = 0.0;
  std::vector<size_t> cuts = InputJumps(v, std::isfinite(score_block_noise) ? score_block_noise : 1e-3);
  cuts.insert(cuts.begin(), 0);
  cuts.push_back(v.size());
  std::vector<std::pair<double, double>> curve;
  for (size_t s = 0; s + 1 < cuts.size(); ++s) {
    const std::vector<double> ts(t.begin() + static_cast<std::ptrdiff_t>(cuts[s]), t.begin() + static_cast<std::ptrdiff_t>(cuts[s + 1]));
    const std::vector<double> vs(v.begin() + static_cast<std::ptrdiff_t>(cuts[s]), v.begin() + static_cast<std::ptrdiff_t>(cuts[s + 1]));
    // Means over ~1 s blocks: short enough that the curve cuts a ramp's corner by a negligible
    // area, long enough to average a fast-sampled log (see MakeProblem).
    std::vector<std::pair<double, double>> pts = {{ts.front(), vs.front()}};
    for (const auto& b : Blocks(ts, std::max(1.0, sample_period_s), sample_period_s)) {
      const double mid = BlockMean(ts, b);
      if (mid > pts.back().first) pts.emplace_back(mid, BlockMean(vs, b));
    }
    if (ts.back() > pts.back().first) pts.emplace_back(ts.back(), vs.back());
    if (s > 0) {
      // Held at the last stretch's end value until just before this stretch's first sample.
      const double hold = ts.front() - 1e-6 * sample_period_s;
      if (hold > curve.back().first) curve.emplace_back(hold, curve.back().second);
    }
    if (pts.size() == 1) {  // a single reading: its own noise, which the whole column's tells
      if (s == 0 && start_sd) {
        std::vector<std::pair<double, double>> all;
        for (size_t k = 0; k < v.size(); ++k) all.emplace_back(t[k], v[k]);
        *start_sd = NoiseAtEveryPoint(all);
      }
      curve.push_back(pts.front());
      continue;
    }
    // The first and last raw readings carry a block's samples' variance each, a block mean's
    // times the samples a block holds (1 at 1 s samples and above).
    const double per_block = std::max(1.0, std::round(1.0 / sample_period_s));
    const Profile piece = LoggedAmbientCurve(pts, score_block_noise, s == 0 ? start_sd : nullptr, 1.0 / per_block);
    for (double b : piece.Breakpoints()) curve.emplace_back(b, piece.Value(b));
  }
  return Profile::Table(curve);
}

sim::SolverOptions SolverForData(double score_block_noise) {
  sim::SolverOptions o;
  const double tol = std::isfinite(score_block_noise) ? std::clamp(0.1 * score_block_noise / 1.5e4, 1e-10, 1e-6) : 1e-9;
  o.cvode.rtol = tol;
  o.cvode.atol = tol;
  return o;
}

}  // namespace rlg::diagnosis
