#include "diagnosis/statistics/off_span.h"

#include <cmath>
#include <stdexcept>
#include <utility>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace rlg::diagnosis {
namespace {

/// The first index in [from, n) whose value is not v (n if none): eight values a test, as four
/// pairs compared at once where SSE2 is, then one by one.
size_t StepEnd(const double* c, size_t from, size_t n, double v) {
  size_t j = from;
#if defined(__SSE2__)
  const __m128d vv = _mm_set1_pd(v);
  for (; j + 8 <= n; j += 8) {
    const __m128d a = _mm_and_pd(_mm_cmpeq_pd(_mm_loadu_pd(c + j), vv), _mm_cmpeq_pd(_mm_loadu_pd(c + j + 2), vv));
    const __m128d b = _mm_and_pd(_mm_cmpeq_pd(_mm_loadu_pd(c + j + 4), vv), _mm_cmpeq_pd(_mm_loadu_pd(c + j + 6), vv));
    if (_mm_movemask_pd(_mm_and_pd(a, b)) != 3) break;
  }
#endif
  while (j < n && c[j] == v) ++j;
  return j;
}

}  // namespace

SpanComplement::SpanComplement(Eigen::MatrixXd Q, Eigen::VectorXd e) : Q_(std::move(Q)), e_(std::move(e)) {
  if (e_.size() != Q_.rows()) throw std::invalid_argument("SpanComplement: residual and basis differ in rows");
  const Eigen::Index rows = Q_.rows();
  Q_prefix_.resize(Q_.cols(), rows + 1);
  e_prefix_.resize(rows + 1);
  Q_prefix_.col(0).setZero();
  e_prefix_[0] = 0.0;
  for (Eigen::Index i = 0; i < rows; ++i) {
    Q_prefix_.col(i + 1) = Q_prefix_.col(i) + Q_.row(i).transpose();
    e_prefix_[i + 1] = e_prefix_[i] + e_[i];
  }
  Qe_ = Q_.transpose() * e_;
}

bool SpanComplement::Steps(const std::vector<std::pair<const double*, size_t>>& runs, OffSpan* out) const {
  const auto most = static_cast<size_t>(Q_.rows() / 4);
  Eigen::Index at = 0;
  double raw = 0.0;
  for (const auto& [c, n] : runs) {
    const size_t first = out->steps.size();
    double sum = 0.0;
    for (size_t k = 0; k < n;) {
      const size_t j = StepEnd(c, k + 1, n, c[k]);
      if (out->steps.size() == most || !std::isfinite(c[k])) return false;
      out->steps.push_back({at + static_cast<Eigen::Index>(k), at + static_cast<Eigen::Index>(j), c[k]});
      sum += c[k] * static_cast<double>(j - k);
      k = j;
    }
    const double mean = n == 0 ? 0.0 : sum / static_cast<double>(n);
    for (size_t i = first; i < out->steps.size(); ++i) {
      OffSpan::Step& s = out->steps[i];
      s.value -= mean;
      raw += s.value * s.value * static_cast<double>(s.end - s.begin);
    }
    at += static_cast<Eigen::Index>(n);
  }
  out->q = Eigen::VectorXd::Zero(Q_.cols());
  for (const auto& s : out->steps) out->q += s.value * (Q_prefix_.col(s.end) - Q_prefix_.col(s.begin));
  out->xx = raw - out->q.squaredNorm();
  return out->xx > 1e-6 * raw;
}

OffSpan SpanComplement::Project(const std::vector<std::pair<const double*, size_t>>& runs) const {
  size_t total = 0;
  for (const auto& run : runs) total += run.second;
  if (static_cast<Eigen::Index>(total) != Q_.rows()) throw std::invalid_argument("SpanComplement: column and basis differ in rows");
  OffSpan out;
  if (Steps(runs, &out)) return out;
  out = OffSpan{};
  Eigen::VectorXd& x = out.x;
  x.resize(Q_.rows());
  Eigen::Index at = 0;
  for (const auto& [c, n] : runs) {
    const Eigen::Map<const Eigen::VectorXd> v(c, static_cast<Eigen::Index>(n));
    x.segment(at, v.size()) = v.array() - v.mean();
    at += v.size();
  }
  const double raw = x.squaredNorm();
  x -= Q_ * (Q_.transpose() * x);
  out.xx = x.squaredNorm();
  // A column within the regressors' span (to round-off of its own size) adds nothing.
  out.within_span = !(out.xx > 1e-12 * raw);
  if (out.within_span) x.resize(0);
  return out;
}

double SpanComplement::Gain(const OffSpan& c) const {
  if (c.none) return -1.0;
  if (c.within_span) return 0.0;
  double xe = 0.0;
  if (c.steps.empty()) {
    xe = c.x.dot(e_);
  } else {
    for (const auto& s : c.steps) xe += s.value * (e_prefix_[s.end] - e_prefix_[s.begin]);
    xe -= c.q.dot(Qe_);
  }
  return xe * xe / c.xx;
}

}  // namespace rlg::diagnosis
