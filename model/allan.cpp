#include "model/allan.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <limits>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "sim/errors.h"
#include "sim/noise.h"
#include "sim/stats.h"

namespace rlg::model {

AllanCurve OverlappingAllan(const std::vector<double>& y, double dt_s, int min_clusters, size_t max_points) {
  AllanCurve c;
  const size_t n = y.size();
  // Cumulative angle: theta_k = dt sum_{i<k} y_i, so the mean over m samples starting at i is
  // (theta_{i+m} - theta_i) / (m dt).
  std::vector<double> theta(n + 1, 0.0);
  for (size_t i = 0; i < n; ++i) theta[i + 1] = theta[i] + y[i] * dt_s;
  std::vector<size_t> m_of, terms;  // per octave j: m = 2^j samples, n + 1 - 2m differences
  for (size_t m = 1; min_clusters * m <= n && m_of.size() < max_points; m *= 2) {
    m_of.push_back(m);
    terms.push_back(n + 1 - 2 * m);
  }
  // Each octave's sum of squared second differences, in increasing k as one loop per octave
  // would add them (the same bytes), a block of kBlock differences at a time: first the squares
  // of every octave with differences in the block (independent of each other: the compiler
  // vectorizes them), then the sums, kSide octaves side by side in registers so that their
  // addition chains overlap instead of adding up. Difference k belongs to octave j while
  // k < terms[j] (terms falls with j, so the octaves of a block are a prefix); an octave's squares
  // past its last difference, and those of the slots that fill up the last group, are 0, and
  // x + 0 is x: they add nothing (x >= 0 here, a sum of squares).
  constexpr size_t kBlock = 128, kSide = 4;
  const size_t octaves = m_of.size();
  const size_t slots = (octaves + kSide - 1) / kSide * kSide;
  std::vector<double> sum(slots, 0.0), squares(slots * kBlock);
  size_t active = octaves;
  for (size_t k0 = 0; octaves > 0 && k0 < terms[0]; k0 += kBlock) {
    while (terms[active - 1] <= k0) --active;
    const size_t used = (active + kSide - 1) / kSide * kSide;
    for (size_t j = 0; j < used; ++j) {
      double* sq = &squares[j * kBlock];
      const size_t count = j < active ? std::min(kBlock, terms[j] - k0) : 0;
      const double* t = &theta[k0];
      const size_t m = j < active ? m_of[j] : 0;
      for (size_t i = 0; i < count; ++i) {
        const double d = t[i + 2 * m] - 2.0 * t[i + m] + t[i];
        sq[i] = d * d;
      }
      std::fill(sq + count, sq + kBlock, 0.0);
    }
    for (size_t j = 0; j < used; j += kSide) {
      const double* sq = &squares[j * kBlock];
      double s0 = sum[j], s1 = sum[j + 1], s2 = sum[j + 2], s3 = sum[j + 3];
      for (size_t i = 0; i < kBlock; ++i) {
        s0 += sq[i];
        s1 += sq[kBlock + i];
        s2 += sq[2 * kBlock + i];
        s3 += sq[3 * kBlock + i];
      }
      sum[j] = s0;
      sum[j + 1] = s1;
      sum[j + 2] = s2;
      sum[j + 3] = s3;
    }
  }
  for (size_t j = 0; j < octaves; ++j) {
    const double tau = static_cast<double>(m_of[j]) * dt_s;
    c.tau_s.push_back(tau);
    c.adev.push_back(std::sqrt(sum[j] / (2.0 * tau * tau * static_cast<double>(terms[j]))));
    c.n_samples.push_back(static_cast<double>(terms[j]));
  }
  return c;
}

AllanCurve WithMinClusters(const AllanCurve& curve, size_t samples, int min_clusters) {
  size_t points = 0;
  for (size_t m = 1; points < curve.tau_s.size() && min_clusters * m <= samples; m *= 2) ++points;
  AllanCurve c;
  c.tau_s.assign(curve.tau_s.begin(), curve.tau_s.begin() + static_cast<std::ptrdiff_t>(points));
  c.adev.assign(curve.adev.begin(), curve.adev.begin() + static_cast<std::ptrdiff_t>(points));
  c.n_samples.assign(curve.n_samples.begin(), curve.n_samples.begin() + static_cast<std::ptrdiff_t>(points));
  return c;
}

double AllanVarianceRelativeError(const AllanCurve& c, size_t i) {
  const double m = c.tau_s[i] / c.tau_s.front();
  return std::sqrt(std::max(2.0 * m / c.n_samples[i], 1e-12));
}

double SamplePeriod(const std::vector<double>& t_s) {
  if (t_s.size() < 2) throw InputError(fmt::format("a sample period needs two samples; the record has {}", t_s.size()));
  // Evenly sampled (a simulation's times, most logs): every step is the first, which is then
  // the median, without a copy or a selection (~1.5 % of a population gyro's CPU). Only for a
  // positive step below 2^1022, where the mean of two middle steps is the step exactly (a zero
  // step's sign, or an overflow, could differ).
  const double first = t_s[1] - t_s[0];
  if (first > 0.0 && first <= 0x1p1022) {
    size_t k = 1;
    while (k + 1 < t_s.size() && t_s[k + 1] - t_s[k] == first) ++k;
    if (k + 1 == t_s.size()) return first;
  }
  std::vector<double> steps(t_s.size() - 1);
  for (size_t k = 0; k + 1 < t_s.size(); ++k) steps[k] = t_s[k + 1] - t_s[k];
  const auto mid = steps.begin() + static_cast<std::ptrdiff_t>(steps.size() / 2);
  std::nth_element(steps.begin(), mid, steps.end());
  if (steps.size() % 2 == 1) return *mid;
  const double upper = *mid;
  return 0.5 * (upper + *std::max_element(steps.begin(), mid));
}

namespace {

// Two times that differ by less than this relative amount are the same averaging time: time
// stamps written with 6+ significant digits reproduce a sample period only to ~1e-9.
constexpr double kSameTime = 1e-6;

}  // namespace

bool Stability::adjusted() const { return std::abs(averaging_s - requested_s) > kSameTime * requested_s; }

namespace {

/// A Stability's blocks (everything but sigma) for a record of `samples` samples; the errors of
/// BiasStability.
Stability StabilityBlocks(size_t samples, double dt_s, double tau_s, BelowSamplePeriod below) {
  if (!(dt_s > 0.0) || !(tau_s > 0.0)) {
    throw InputError(fmt::format("bias stability needs a positive sample period and averaging time (got {:g} s and {:g} s)",
                                 dt_s, tau_s));
  }
  Stability s;
  s.requested_s = tau_s;
  s.below_sample_period = tau_s < dt_s * (1.0 - kSameTime);
  if (s.below_sample_period && below == BelowSamplePeriod::kRefuse) {
    throw InputError(fmt::format("averaging time {:g} s is below the {:g} s sample period: a stability can be computed "
                                 "over whole samples only, {:g} s or longer",
                                 tau_s, dt_s, dt_s));
  }
  s.samples_per_block = std::max<size_t>(1, static_cast<size_t>(std::llround(tau_s / dt_s)));
  s.averaging_s = static_cast<double>(s.samples_per_block) * dt_s;
  s.blocks = samples / s.samples_per_block;
  if (s.blocks < 2) {
    throw InputError(fmt::format("bias stability at {:g} s needs at least two {:g} s blocks; the run has {} samples of {:g} s",
                                 tau_s, s.averaging_s, samples, dt_s));
  }
  return s;
}

/// sim::StdDev of two vectors of one length, side by side (as MeanPair): the same values.
std::array<double, 2> StdDevPair(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() < 2) return {0.0, 0.0};
  const std::array<double, 2> mean = MeanPair(a, b);
  double sa = 0.0, sb = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    sa += (a[i] - mean[0]) * (a[i] - mean[0]);
    sb += (b[i] - mean[1]) * (b[i] - mean[1]);
  }
  const auto dof = static_cast<double>(a.size() - 1);
  return {std::sqrt(sa / dof), std::sqrt(sb / dof)};
}

}  // namespace

std::vector<double> BlockMeans(const std::vector<double>& y, size_t m) {
  std::vector<double> means(y.size() / m);
  for (size_t b = 0; b < means.size(); ++b) {
    double sum = 0.0;
    for (size_t i = b * m; i < (b + 1) * m; ++i) sum += y[i];
    means[b] = sum / static_cast<double>(m);
  }
  return means;
}

std::array<double, 2> MeanPair(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() != b.size()) throw std::invalid_argument("MeanPair: records of different lengths");
  if (a.empty()) return {0.0, 0.0};
  double sa = 0.0, sb = 0.0;
  for (size_t i = 0; i < a.size(); ++i) {
    sa += a[i];
    sb += b[i];
  }
  const auto n = static_cast<double>(a.size());
  return {sa / n, sb / n};
}

Stability BiasStability(const std::vector<double>& y, double dt_s, double tau_s, BelowSamplePeriod below) {
  Stability s = StabilityBlocks(y.size(), dt_s, tau_s, below);
  if (s.samples_per_block == 1) {  // blocks of one sample: the means are the samples (0 + y / 1 is y, but for a zero's sign)
    s.sigma = sim::StdDev(y);
  } else {
    s.sigma = sim::StdDev(BlockMeans(y, s.samples_per_block));
  }
  return s;
}

std::array<Stability, 2> BiasStabilityPair(const std::vector<double>& a, const std::vector<double>& b, double dt_s,
                                           double tau_s, BelowSamplePeriod below,
                                           std::array<std::vector<double>, 2>* block_means) {
  if (a.size() != b.size()) throw std::invalid_argument("BiasStabilityPair: records of different lengths");
  std::array<Stability, 2> s;
  s[0] = s[1] = StabilityBlocks(a.size(), dt_s, tau_s, below);
  const size_t m = s[0].samples_per_block;
  std::array<std::vector<double>, 2> means;
  if (m > 1 || block_means) {
    // BlockMeans of both, side by side.
    means[0].resize(s[0].blocks);
    means[1].resize(s[0].blocks);
    for (size_t k = 0; k < s[0].blocks; ++k) {
      double sa = 0.0, sb = 0.0;
      for (size_t i = k * m; i < (k + 1) * m; ++i) {
        sa += a[i];
        sb += b[i];
      }
      means[0][k] = sa / static_cast<double>(m);
      means[1][k] = sb / static_cast<double>(m);
    }
  }
  const std::array<double, 2> sigma = m == 1 ? StdDevPair(a, b) : StdDevPair(means[0], means[1]);
  s[0].sigma = sigma[0];
  s[1].sigma = sigma[1];
  if (block_means) *block_means = std::move(means);
  return s;
}

std::string DescribeAveraging(const Stability& s, double dt_s) {
  if (!s.adjusted()) return fmt::format("{:g} s", s.averaging_s);
  if (s.below_sample_period) {
    return fmt::format("{:g} s (one sample: {:g} s is below the {:g} s sample period)", s.averaging_s, s.requested_s, dt_s);
  }
  return fmt::format("{:g} s ({} samples of {:g} s: {:g} s is not a whole number of samples)", s.averaging_s,
                     s.samples_per_block, dt_s, s.requested_s);
}

double AllanVariance(const NoiseTerms& t, double tau) {
  return 3.0 * t.quantization * t.quantization / (tau * tau) + t.arw * t.arw / tau +
         std::pow(sim::kFlickerFloor * t.bias_instability, 2) + t.rrw * t.rrw * tau / 3.0;
}

namespace {

// Basis of sigma²(tau), in NoiseTerm order: 1/tau², 1/tau, 1, tau. Coefficients: 3Q², N²,
// (0.664B)², K²/3.
double Basis(int j, double tau) {
  switch (j) {
    case 0: return 1.0 / (tau * tau);
    case 1: return 1.0 / tau;
    case 2: return 1.0;
    default: return tau;
  }
}

// Coefficient of Basis(j) -> the term's value (NoiseTerms units), and the whole vector.
double TermValue(int j, double coefficient) {
  const double c = std::max(coefficient, 0.0);
  switch (j) {
    case 0: return std::sqrt(c / 3.0);
    case 1: return std::sqrt(c);
    case 2: return std::sqrt(c) / sim::kFlickerFloor;
    default: return std::sqrt(3.0 * c);
  }
}

/// The weighted least-squares fits of the four-term model on every subset of its terms (mask
/// bit j: term j), for the non-negative fit: a subset with a negative coefficient or more terms
/// than points is not feasible.
struct SubsetFits {
  bool any = false;  ///< false: no curve, or a constant record (every coefficient 0)
  std::array<bool, 16> feasible{};
  std::array<Eigen::Vector4d, 16> coefficients;  ///< in NoiseTerm order, 0 for the terms left out
  std::array<double, 16> cost{};                 ///< weighted sum of squared residuals
  std::array<int, 16> terms{};
};

SubsetFits FitSubsets(const AllanCurve& c) {
  SubsetFits out;
  const auto p = static_cast<Eigen::Index>(c.tau_s.size());
  double largest = 0.0;
  for (double a : c.adev) largest = std::max(largest, a * a);
  if (p == 0 || !(largest > 0.0)) return out;  // no curve, or a constant record
  out.any = true;
  Eigen::MatrixXd A(p, 4);
  Eigen::VectorXd b(p);
  for (Eigen::Index i = 0; i < p; ++i) {
    const double tau = c.tau_s[i];
    // A point of exactly zero variance (a constant stretch) would get an infinite weight: floor
    // it at round-off relative to the largest point.
    const double avar = std::max(c.adev[i] * c.adev[i], 1e-15 * largest);
    // Divide rows by avar * its relative error so each point counts by its own uncertainty.
    const double w = 1.0 / (avar * AllanVarianceRelativeError(c, static_cast<size_t>(i)));
    for (int j = 0; j < 4; ++j) A(i, j) = w * Basis(j, tau);
    b[i] = avar * w;
  }
  for (int mask = 1; mask < 16; ++mask) {
    std::vector<int> cols;
    for (int j = 0; j < 4; ++j)
      if (mask & (1 << j)) cols.push_back(j);
    if (static_cast<Eigen::Index>(cols.size()) > p) continue;
    Eigen::MatrixXd As(p, static_cast<Eigen::Index>(cols.size()));
    for (size_t j = 0; j < cols.size(); ++j) As.col(static_cast<Eigen::Index>(j)) = A.col(cols[j]);
    const Eigen::VectorXd x = As.colPivHouseholderQr().solve(b);
    if ((x.array() < 0.0).any()) continue;
    out.feasible[mask] = true;
    out.cost[mask] = (As * x - b).squaredNorm();
    out.terms[mask] = static_cast<int>(cols.size());
    out.coefficients[mask].setZero();
    for (size_t j = 0; j < cols.size(); ++j) out.coefficients[mask][cols[j]] = x[static_cast<Eigen::Index>(j)];
  }
  return out;
}

/// Non-negative least squares of the four-term model: of every subset, the feasible fit of the
/// lowest cost + per_term k for k terms (0: the lowest cost, every term the curve allows).
Eigen::Vector4d FitCoefficients(const SubsetFits& fits, double per_term) {
  Eigen::Vector4d best = Eigen::Vector4d::Zero();
  if (!fits.any) return best;
  double best_cost = std::numeric_limits<double>::infinity();
  for (int mask = 1; mask < 16; ++mask) {
    if (!fits.feasible[mask]) continue;
    const double cost = fits.cost[mask] + per_term * static_cast<double>(fits.terms[mask]);
    if (cost < best_cost) {
      best_cost = cost;
      best = fits.coefficients[mask];
    }
  }
  return best;
}

NoiseTerms ToTerms(const Eigen::Vector4d& coefficients) {
  NoiseTerms t;
  t.quantization = TermValue(0, coefficients[0]);
  t.arw = TermValue(1, coefficients[1]);
  t.bias_instability = TermValue(2, coefficients[2]);
  t.rrw = TermValue(3, coefficients[3]);
  return t;
}

const char* kPart[4] = {"-1 slope", "-1/2 slope", "flat part", "+1/2 slope"};

std::string Names(const std::vector<int>& terms) {
  std::vector<std::string> names;
  for (int k : terms) names.emplace_back(NoiseTermName(static_cast<NoiseTerm>(k)));
  return fmt::format("{}", fmt::join(names, " and "));
}

}  // namespace

NoiseTerms FitNoiseTerms(const AllanCurve& c) { return ToTerms(FitCoefficients(FitSubsets(c), 0.0)); }

const char* NoiseTermName(NoiseTerm term) {
  static const char* kNames[4] = {"quantization", "ARW", "bias instability", "RRW"};
  return kNames[static_cast<int>(term)];
}

NoiseReadOffs ReadNoiseTerms(const AllanCurve& c) {
  NoiseReadOffs r;
  // The read-offs come from the subset of the lowest AIC, cost + 2 k (rows are in units of
  // each point's own error, so the cost is a chi-square). The lowest cost alone took every
  // term it could: on 60 s samples (a 2 h record is five octaves) quantization's -1 slope took
  // 40 % of the white noise at the first point, and ARW was read 22-27 % low while
  // quantization itself stayed unresolved.
  const SubsetFits fits = FitSubsets(c);
  const Eigen::Vector4d coef = FitCoefficients(fits, 2.0);
  r.fitted = ToTerms(coef);
  r.every_term = ToTerms(FitCoefficients(fits, 0.0));
  const size_t p = c.tau_s.size();
  if (p == 0) {
    for (auto& t : r.terms) t.reason = "the record is too short for an Allan deviation";
    return r;
  }
  r.tau_min_s = c.tau_s.front();
  r.tau_max_s = c.tau_s.back();
  // Per point: each term's share of the fitted variance, the leading term, the point's error.
  std::vector<std::array<double, 4>> share(p);
  std::vector<int> leader(p, -1);
  std::vector<double> rel(p);
  for (size_t i = 0; i < p; ++i) {
    rel[i] = AllanVarianceRelativeError(c, i);
    double total = 0.0;
    for (int j = 0; j < 4; ++j) total += coef[j] * Basis(j, c.tau_s[i]);
    for (int j = 0; j < 4; ++j) share[i][j] = total > 0.0 ? coef[j] * Basis(j, c.tau_s[i]) / total : 0.0;
    if (total > 0.0) leader[i] = static_cast<int>(std::max_element(share[i].begin(), share[i].end()) - share[i].begin());
  }
  for (int j = 0; j < 4; ++j) {
    TermReadOff& t = r.terms[static_cast<size_t>(j)];
    t.value = TermValue(j, coef[j]);
    std::vector<size_t> leads;
    for (size_t i = 0; i < p; ++i) {
      if (leader[i] != j) continue;
      leads.push_back(i);
      if (share[i][j] >= 2.0 * rel[i]) t.resolved = true;
    }
    if (t.resolved) continue;
    // What the curve allows: term(tau) <= avar(tau) (1 + 2 rel) at every measured tau.
    double bound = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < p; ++i) {
      bound = std::min(bound, c.adev[i] * c.adev[i] * (1.0 + 2.0 * rel[i]) / Basis(j, c.tau_s[i]));
    }
    t.upper_bound = TermValue(j, bound);
    if (leader.front() < 0) {
      t.reason = "the record is constant: its Allan deviation is zero at every tau";
    } else if (!leads.empty()) {
      size_t best = leads.front();
      for (size_t i : leads) best = rel[i] < rel[best] ? i : best;
      // Clusters of tau in the record: n_samples = samples + 1 - 2 m overlapping differences.
      const double m = c.tau_s[best] / c.tau_s.front();
      const double clusters = std::floor((c.n_samples[best] - 1.0) / m + 2.0);
      t.reason = fmt::format("it leads only at tau = {:g} s, where it is {:.0f} % of the fitted variance but the record holds "
                             "{:.0f} clusters of that length and the measured point is uncertain by ±{:.0f} %",
                             c.tau_s[best], 100.0 * share[best][j], clusters, 100.0 * rel[best]);
    } else {
      std::vector<int> lower, higher;  // leading terms with a falling (lower) or rising (higher) slope than j
      for (size_t i = 0; i < p; ++i) {
        auto& side = leader[i] < j ? lower : higher;
        if (std::find(side.begin(), side.end(), leader[i]) == side.end()) side.push_back(leader[i]);
      }
      std::sort(lower.begin(), lower.end());
      std::sort(higher.begin(), higher.end());
      if (higher.empty()) {
        t.reason = fmt::format("the record is too short to reach its {}: {} still leads at the longest tau, {:g} s",
                               kPart[j], Names({leader.back()}), r.tau_max_s);
      } else if (lower.empty()) {
        t.reason = fmt::format("the samples are too coarse to show its {}: {} already leads at the shortest tau, {:g} s",
                               kPart[j], Names({leader.front()}), r.tau_min_s);
      } else {
        t.reason = fmt::format("it stays below {} at every measured tau ({:g} ... {:g} s)", Names(lower) + " and " +
                               Names(higher), r.tau_min_s, r.tau_max_s);
      }
    }
  }
  return r;
}

double ReportScale(NoiseTerm term) {
  // ARW: °/h x sqrt(s) / 60 = °/sqrt(h); RRW: °/h / sqrt(s) x 60 = °/h/sqrt(h).
  switch (term) {
    case NoiseTerm::kArw: return 1.0 / 60.0;
    case NoiseTerm::kRrw: return 60.0;
    default: return 1.0;
  }
}

std::string FormatReadOff(const NoiseReadOffs& r, NoiseTerm term, int decimals) {
  const TermReadOff& t = r[term];
  if (t.resolved) return fmt::format("{:.{}f}", t.value * ReportScale(term), decimals);
  return fmt::format("not resolved (< {:.{}f})", t.upper_bound * ReportScale(term), decimals);
}

std::vector<std::string> NotResolvedNotes(const std::vector<std::string>& runs, const std::vector<NoiseReadOffs>& readoffs,
                                          const std::vector<NoiseTerm>& terms) {
  std::vector<std::string> notes;
  for (NoiseTerm term : terms) {
    std::vector<std::pair<std::string, std::vector<std::string>>> by_reason;  // in order of first appearance
    for (size_t i = 0; i < readoffs.size(); ++i) {
      const TermReadOff& t = readoffs[i][term];
      if (t.resolved) continue;
      auto it = std::find_if(by_reason.begin(), by_reason.end(), [&](const auto& g) { return g.first == t.reason; });
      if (it == by_reason.end()) it = by_reason.insert(by_reason.end(), {t.reason, {}});
      it->second.push_back(runs[i]);
    }
    for (const auto& [reason, ids] : by_reason) {
      notes.push_back(fmt::format("{} not resolved in {}: {}", NoiseTermName(term), fmt::join(ids, ", "), reason));
    }
  }
  return notes;
}

void AddNoiseTermsJson(const NoiseReadOffs& r, nlohmann::json& out) {
  const std::pair<NoiseTerm, const char*> keys[3] = {{NoiseTerm::kArw, "arw_deg_per_sqrt_h"},
                                                     {NoiseTerm::kBiasInstability, "bias_instability_dph"},
                                                     {NoiseTerm::kRrw, "rrw_deg_per_h_per_sqrt_h"}};
  nlohmann::json not_resolved = nlohmann::json::object();
  for (const auto& [term, key] : keys) {
    const TermReadOff& t = r[term];
    if (t.resolved) {
      out[key] = t.value * ReportScale(term);
    } else {
      out[key] = nullptr;
      not_resolved[key] = {{"reason", t.reason}, {"upper_bound", t.upper_bound * ReportScale(term)}};
    }
  }
  out["not_resolved"] = not_resolved;
}

}  // namespace rlg::model
