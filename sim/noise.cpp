#include "sim/noise.h"

#include <algorithm>
#include <cmath>

namespace rlg::sim {
namespace {

// Allan variance of a stationary first-order Gauss-Markov process of variance s2 and
// correlation time T, averaged over tau: (s2 T² / tau²)(2x - 3 + 4e^-x - e^-2x), x = tau / T.
double MarkovAllanVariance(double s2, double T, double tau) {
  const double x = tau / T;
  if (x < 1e-4) return s2 * x / 3.0 * (1.0 - x / 4.0);  // series: avoids cancellation
  return s2 * (T * T / (tau * tau)) * (2.0 * x - 3.0 + 4.0 * std::exp(-x) - std::exp(-2.0 * x));
}

// Floor through an int64 cast: a conversion instruction instead of a library call on baseline
// x86-64. The cast is defined only inside int64's range: from 2^52 on every double is already
// an integer, and inf or NaN (from an absurd gyro) passes through instead of being undefined.
inline double Floor(double x) {
  if (!(std::abs(x) < 0x1p52)) return x;
  const double t = static_cast<double>(static_cast<int64_t>(x));
  return t > x ? t - 1.0 : t;
}

}  // namespace

Rng::Rng(uint64_t seed, uint64_t stream) {
  // SplitMix64 of (seed, stream): decorrelated streams per run from one user seed.
  uint64_t z = seed * 0x9E3779B97F4A7C15ULL + (stream + 1) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  engine_.seed(z ^ (z >> 31));
}

void Rng::Refill() {
  for (double& d : block_) d = normal_(engine_);
  next_ = 0;
}

std::vector<std::pair<double, double>> GyroNoise::InstabilityTerms(const GyroNoiseParams& p) {
  std::vector<std::pair<double, double>> terms;
  if (p.bias_instability_dph <= 0.0) return terms;
  if (p.instability_model == GyroNoiseParams::InstabilityModel::kGaussMarkov) {
    terms.emplace_back(p.gauss_markov_time_s, p.bias_instability_dph);
    return terms;
  }
  for (int k = 2; k <= 10; ++k) terms.emplace_back(std::pow(10.0, 0.5 * k), 1.0);
  // Scale so that the mean Allan deviation over 30 s ... 3e4 s equals 0.664 B (flicker floor).
  double mean_adev = 0.0;
  int count = 0;
  for (double tau = 30.0; tau <= 3.0e4 * 1.0001; tau *= std::sqrt(10.0), ++count) {
    double avar = 0.0;
    for (const auto& [T, s] : terms) avar += MarkovAllanVariance(s * s, T, tau);
    mean_adev += std::sqrt(avar);
  }
  mean_adev /= count;
  const double scale = 0.664 * p.bias_instability_dph / mean_adev;
  for (auto& t : terms) t.second *= scale;
  return terms;
}

double GyroNoise::InstabilityAllanVariance(const GyroNoiseParams& params, double tau_s) {
  double avar = 0.0;
  for (const auto& [T, s] : InstabilityTerms(params)) avar += MarkovAllanVariance(s * s, T, tau_s);
  return avar;
}

GyroNoise::GyroNoise(const GyroNoiseParams& p, double dt_s, Rng& rng)
    : rng_(rng),
      dt_(dt_s),
      white_sigma_(60.0 * p.arw_deg_per_sqrt_h / std::sqrt(dt_s)),
      rrw_sigma_(p.rrw_deg_per_h_per_sqrt_h * std::sqrt(dt_s) / 60.0),
      turn_on_(p.turn_on_sigma_dph * rng.Normal()),
      q_(p.quantization_arcsec),
      inv_q_(q_ > 0.0 ? 1.0 / q_ : 0.0),
      q_over_dt_(q_ / dt_s) {
  int64_t previous_every = 1;
  for (const auto& [T, sigma] : InstabilityTerms(p)) {
    // A term with T >> dt barely moves in one sample: update it every `every` <= T / (10 dt)
    // samples with the exact transition over that interval and hold it in between. Each jump
    // is then at most sigma sqrt(2 / 10) ~ 0.45 sigma (~5e-4 °/h for the default gyro), far
    // below the white noise of a sample, and the Allan deviation at tau >= every dt is
    // unchanged. It cuts the random draws per sample from 9 to ~1.5. The intervals are powers
    // of 3, so each divides the next (terms come by increasing T): a term can only be due when
    // the one before it is, and a sample costs one countdown.
    int64_t every = 1;
    while (every * 3 <= static_cast<int64_t>(T / (10.0 * dt_s))) every *= 3;
    every = std::max(every, previous_every);
    const double phi = std::exp(-static_cast<double>(every) * dt_s / T);
    const auto ratio = static_cast<int>(every / previous_every);
    markov_.push_back({phi, sigma * std::sqrt(1.0 - phi * phi), sigma * rng_.Normal(), ratio, ratio});  // stationary start
    instability_ += markov_.back().value;
    previous_every = every;
  }
}

double GyroNoise::Sample(double true_rate_dph) {
  // The instability terms enter with the values they held over this sample, then the due ones
  // advance, in order of increasing T (the order of the random draws).
  double y = true_rate_dph + turn_on_ + rrw_ + instability_;
  for (auto& m : markov_) {
    if (--m.left != 0) break;
    m.left = m.ratio;
    const double next = m.phi * m.value + m.drive * rng_.Normal();
    instability_ += next - m.value;  // rounding drift ~1e-16 sqrt(updates) of a term: negligible
    m.value = next;
  }
  if (white_sigma_ > 0.0) y += white_sigma_ * rng_.Normal();
  if (rrw_sigma_ > 0.0) rrw_ += rrw_sigma_ * rng_.Normal();
  if (q_ <= 0.0) return y;
  angle_arcsec_ += y * dt_;  // °/h x s = arcsec
  const double pulses = Floor(angle_arcsec_ * inv_q_);
  const double out = (pulses - pulses_) * q_over_dt_;
  pulses_ = pulses;
  return out;
}

}  // namespace rlg::sim
