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
///
/// The random sequence (what "same seed -> same bytes" rests on; changing any of it changes
/// every seeded output, README "Speed"):
///   engines    four PCG64 "fast" engines per Rng (pcg-cpp's pcg64_fast = PCG XSL-RR 128/64 on
///              a 128-bit multiplicative congruential state), read as lanes in turn: word k of
///              a block comes from lane k mod 4 (independent chains, so their 128-bit multiplies
///              overlap in the pipeline)
///   normals    a ziggurat on Boost.Random's 128-layer tables (boost::random::detail::
///              normal_table<double>; Marsaglia & Tsang's method), made kBlock = 256 at a time:
///              draw j of a block takes word j: bits 0-6 the layer i, bit 7 the sign, bits
///              12-63 a uniform r in [0, 1), x = r X[i]; accepted when x < X[i + 1] (~99 %).
///              The others are then completed in block order from further words of lane 0:
///              the wedge test (a uniform y between the layer's Y values against exp(-x²/2)),
///              the tail beyond X[1] (Marsaglia's exponential method, two words a try), or a
///              whole fresh candidate after a rejection. Each number is an exact standard
///              normal draw; exp and log appear only in those rare completions
///   seeding    Rng(seed, stream, substream): SplitMix64 of the key k = Mix(Mix(Mix(seed) ^ stream)
///              ^ substream) gives eight words: lane j's 128-bit state is words 2j, 2j + 1 (see
///              Rng::Rng)
///   substreams each noise source of a run draws from its own substream, in sample order, so
///              that drawing in blocks, one sample at a time or one source before another gives
///              the same numbers (kSubstream* below):
///                0  ARW white noise, one draw per sample
///                1  turn-on bias (one draw), the instability terms' stationary starts (by
///                   increasing correlation time), then their updates (per sample, by
///                   increasing correlation time)
///                2  rate random walk, one draw per sample
///                3 + i  temperature sensor i (the gyro file's order), one draw per sample
///              A source whose sigma is 0 draws nothing.

#include <pcg_random.hpp>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace rlg::sim {

/// The flicker floor of an Allan deviation: sigma_min = 0.664 B for a bias instability B (1/f
/// noise; IEEE Std 952-1997, Annex C: sqrt(2 ln 2 / pi) = 0.6643, rounded as the standard
/// reads B = sigma_min / 0.664).
inline constexpr double kFlickerFloor = 0.664;

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

/// Substreams of a run's noise sources (see the sequence at the top of this file).
inline constexpr uint64_t kSubstreamArw = 0, kSubstreamInstability = 1, kSubstreamRrw = 2, kSubstreamSensor0 = 3;

/// Standard normal draws of one noise source: substream `substream` of run `stream` of the
/// user's `seed` (the sequence at the top of this file). Normal() hands them out one at a time
/// from a block; Fill() writes the next n into the caller's buffer, whole blocks straight into
/// it. Both continue one sequence: n calls of Normal() and one Fill(n) give the same numbers.
/// A draw costs ~2 ns in blocks (BM_NormalFill), 2.6 one at a time (BM_NormalDraw): the floor
/// under the simulator's noise (docs/performance.md, "Simulation").
class Rng {
 public:
  static constexpr size_t kBlock = 256;
  Rng(uint64_t seed, uint64_t stream, uint64_t substream = 0);
  double Normal() {
    if (next_ == kBlock) {
      Generate(block_.data());
      next_ = 0;
    }
    return block_[next_++];
  }
  /// The next n draws into out[0..n).
  void Fill(double* out, size_t n);

 private:
  static constexpr int kLanes = 4;
  void Generate(double* out);  // the next kBlock draws
  double Complete(uint64_t word);  // a candidate outside its layer's rectangle, from lane 0 on
  std::array<pcg64_fast, kLanes> lanes_;
  std::array<double, kBlock> block_;
  size_t next_ = kBlock;
};

/// A gyro's noise over consecutive samples of length dt_s. Sample() takes one sample, Apply()
/// a block of them in place (the simulator's path: its draws come in blocks and the white
/// noise and the quantizer run as loops the compiler vectorises); the two give the same
/// numbers for the same samples, whatever the blocks.
class GyroNoise {
 public:
  /// Draws from substreams kSubstreamArw...kSubstreamRrw of (seed, stream).
  GyroNoise(const GyroNoiseParams& params, double dt_s, uint64_t seed, uint64_t stream);
  /// Measured rate for a true rate over the next sample (°/h).
  double Sample(double true_rate_dph) {
    Apply(&true_rate_dph, 1);
    return true_rate_dph;
  }
  /// Replaces the true rates of the next n samples (°/h) by the measured ones.
  void Apply(double* rate_dph, size_t n);

  /// Analytic Allan variance ((°/h)²) of the bias-instability process at averaging time tau,
  /// used to scale the flicker approximation (and by tests).
  static double InstabilityAllanVariance(const GyroNoiseParams& params, double tau_s);
  /// The bias-instability process as first-order Gauss-Markov terms (correlation time T in s,
  /// sigma in °/h), summed: one term for "gauss_markov", nine for "flicker"; none without it.
  /// Its covariance is what the hidden-effect harness weighs a difference of two answers by.
  static std::vector<std::pair<double, double>> InstabilityTerms(const GyroNoiseParams& p);

 private:
  static constexpr size_t kChunk = Rng::kBlock;  // samples per inner block: whole blocks of draws, in L1
  void ApplyChunk(double* y, size_t n);

  struct Markov {
    double phi;    // exp(-every dt / T)
    double drive;  // sigma sqrt(1 - phi²)
    double value;
    int ratio;     // updates of the previous term per update of this one (samples for the first)
    int left;      // countdown to the next update, in the same unit
  };

  Rng arw_rng_, instability_rng_, rrw_rng_;
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
  std::array<double, kChunk> scratch_;  // a chunk's white or random-walk draws, then its angles
  std::vector<double> instability_draws_;  // a chunk's instability draws
};

struct SensorNoiseParams {
  double sigma_C = 0.0;
  double resolution_C = 0.0;  ///< 0 = continuous
};

/// Noisy, quantized temperature reading: T + sigma n, rounded half away from zero to a
/// multiple of the resolution. A value that is not finite or whose multiple of the resolution
/// reaches 2^52 (a double without fraction) passes through unrounded, for the simulator's limits
/// to refuse.
class SensorNoise {
 public:
  explicit SensorNoise(const SensorNoiseParams& p)
      : sigma_(p.sigma_C), resolution_(p.resolution_C), inv_resolution_(p.resolution_C > 0.0 ? 1.0 / p.resolution_C : 0.0) {}
  double Read(double T_C, Rng& rng) const {
    ReadInPlace(&T_C, 1, rng);
    return T_C;
  }
  /// Replaces n true temperatures by their readings, with n draws of rng in order (the same
  /// numbers as n calls of Read).
  void ReadInPlace(double* T_C, size_t n, Rng& rng) const;

 private:
  double sigma_, resolution_, inv_resolution_;  // a multiply, not a divide, per sample
};

}  // namespace rlg::sim
