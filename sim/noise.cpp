#include "sim/noise.h"

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

}  // namespace

Rng::Rng(uint64_t seed, uint64_t stream) {
  // SplitMix64 of (seed, stream): decorrelated streams per run from one user seed.
  uint64_t z = seed * 0x9E3779B97F4A7C15ULL + (stream + 1) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  engine_.seed(z ^ (z >> 31));
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
      q_(p.quantization_arcsec) {
  for (const auto& [T, sigma] : InstabilityTerms(p)) {
    const double phi = std::exp(-dt_s / T);
    markov_.push_back({phi, sigma * std::sqrt(1.0 - phi * phi), sigma * rng_.Normal()});  // stationary start
  }
}

double GyroNoise::Sample(double true_rate_dph) {
  double y = true_rate_dph + turn_on_ + rrw_;
  for (auto& m : markov_) {
    y += m.value;
    m.value = m.phi * m.value + m.drive * rng_.Normal();
  }
  if (white_sigma_ > 0.0) y += white_sigma_ * rng_.Normal();
  if (rrw_sigma_ > 0.0) rrw_ += rrw_sigma_ * rng_.Normal();
  if (q_ <= 0.0) return y;
  angle_arcsec_ += y * dt_;  // °/h x s = arcsec
  const double pulses = std::floor(angle_arcsec_ / q_);
  const double out = (pulses - pulses_) * q_ / dt_;
  pulses_ = pulses;
  return out;
}

double ReadSensor(double T_C, const SensorNoiseParams& p, Rng& rng) {
  double v = T_C;
  if (p.sigma_C > 0.0) v += p.sigma_C * rng.Normal();
  if (p.resolution_C > 0.0) v = std::round(v / p.resolution_C) * p.resolution_C;
  return v;
}

}  // namespace rlg::sim
