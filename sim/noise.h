#pragma once
/// Gyro and temperature-sensor noise, seeded and reproducible. Boost.Random's distributions
/// are specified exactly (unlike std::normal_distribution), so one seed gives the same bytes
/// on every platform; its normal distribution is a fast ziggurat.
///
/// Gyro output over a sample of length dt (s), in °/h:
///   y_k = B_k + n_arw + b_bi + r_rrw + turn-on, then quantized as angle pulses
///   n_arw  white, sigma = 60 N / sqrt(dt)            N: ARW in °/sqrt(h) (sigma(tau) = N / sqrt(tau_h))
///   b_bi   bias instability B: "flicker" (default) = sum of first-order Gauss-Markov terms with
///          correlation times spaced half a decade from 10 s to 1e5 s, scaled so the Allan
///          deviation is ~flat at 0.664 B across 30 s...3e4 s (IEEE 952 read-off B = sigma_min/0.664);
///          or "gauss_markov": one term with correlation time tau_c and sigma = B
///   r_rrw  random walk, increments sigma = K sqrt(dt) / 60   K: RRW in °/h/sqrt(h)
///   quantization: the integrated angle (arcsec; °/h x s = arcsec) is read in whole pulses of Q
/// Temperature sensor: T + white noise sigma, rounded to a resolution step.

#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace rlg::sim {

struct GyroNoiseParams {
  double arw_deg_per_sqrt_h = 0.0;
  double bias_instability_dph = 0.0;
  enum class InstabilityModel { kFlicker, kGaussMarkov };
  InstabilityModel instability_model = InstabilityModel::kFlicker;
  double gauss_markov_time_s = 3600.0;
  double rrw_deg_per_h_per_sqrt_h = 0.0;
  double quantization_arcsec = 0.0;  ///< 0 = no quantization
  double turn_on_sigma_dph = 0.0;    ///< run-to-run constant bias
};

/// Random-number source of one run: a 64-bit Mersenne twister seeded from (seed, stream),
/// giving standard normal draws. The draws are made kBlock at a time in a tight loop and
/// handed out in order, so the sequence is exactly that of one draw per call; one costs
/// ~5.7 ns (BM_NormalDraw), the floor under the simulator's noise (README, "Speed").
class Rng {
 public:
  Rng(uint64_t seed, uint64_t stream);
  double Normal() {
    if (next_ == kBlock) Refill();
    return block_[next_++];
  }

 private:
  static constexpr size_t kBlock = 512;
  void Refill();
  boost::random::mt19937_64 engine_;
  boost::random::normal_distribution<double> normal_;
  std::array<double, kBlock> block_;
  size_t next_ = kBlock;
};

class GyroNoise {
 public:
  GyroNoise(const GyroNoiseParams& params, double dt_s, Rng& rng);
  /// Measured rate for a true rate over the next sample (°/h).
  double Sample(double true_rate_dph);

  /// Analytic Allan variance ((°/h)²) of the bias-instability process at averaging time tau,
  /// used to scale the flicker approximation (and by tests).
  static double InstabilityAllanVariance(const GyroNoiseParams& params, double tau_s);
  /// The bias-instability process as first-order Gauss-Markov terms (correlation time T in s,
  /// sigma in °/h), summed: one term for "gauss_markov", nine for "flicker"; none without it.
  /// Its covariance is what the hidden-effect harness weighs a difference of two answers by.
  static std::vector<std::pair<double, double>> InstabilityTerms(const GyroNoiseParams& p);

 private:
  struct Markov {
    double phi;    // exp(-every dt / T)
    double drive;  // sigma sqrt(1 - phi²)
    double value;
    int ratio;     // updates of the previous term per update of this one (samples for the first)
    int left;      // countdown to the next update, in the same unit
  };

  Rng& rng_;
  double dt_;
  double white_sigma_;
  double rrw_sigma_;
  double rrw_ = 0.0;
  double turn_on_;
  double q_;
  double inv_q_;       // 1 / q_ (0 without quantization)
  double q_over_dt_;   // one pulse as a rate, °/h
  double angle_arcsec_ = 0.0;
  double pulses_ = 0.0;
  std::vector<Markov> markov_;  // by increasing correlation time
  double instability_ = 0.0;    // sum of the terms' held values
};

struct SensorNoiseParams {
  double sigma_C = 0.0;
  double resolution_C = 0.0;  ///< 0 = continuous
};

/// Noisy, quantized temperature reading: T + sigma n, rounded half away from zero to a
/// multiple of the resolution.
class SensorNoise {
 public:
  explicit SensorNoise(const SensorNoiseParams& p)
      : sigma_(p.sigma_C), resolution_(p.resolution_C), inv_resolution_(p.resolution_C > 0.0 ? 1.0 / p.resolution_C : 0.0) {}
  double Read(double T_C, Rng& rng) const {
    double v = T_C;
    if (sigma_ > 0.0) v += sigma_ * rng.Normal();
    if (resolution_ > 0.0) {
      // Half away from zero through an int64 cast: one conversion instruction and no library
      // call (std::round is one on baseline x86-64). The cast is defined only inside int64's
      // range; from 2^52 on a double has no fraction to round, and NaN passes through (the
      // simulator's limits then refuse the run), so the well-predicted branch costs nothing.
      const double scaled = v * inv_resolution_ + std::copysign(0.5, v);
      if (std::abs(scaled) < 0x1p52) v = static_cast<double>(static_cast<int64_t>(scaled)) * resolution_;
    }
    return v;
  }

 private:
  double sigma_, resolution_, inv_resolution_;  // a multiply, not a divide, per sample
};

}  // namespace rlg::sim
