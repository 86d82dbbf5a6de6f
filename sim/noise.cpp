#include "sim/noise.h"

#include <algorithm>
#include <boost/random/normal_distribution.hpp>
#include <cmath>
#include <cstring>
#include <type_traits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "sim/simd.h"

namespace rlg::sim {
namespace {

// Allan variance of a stationary first-order Gauss-Markov process of variance s2 and
// correlation time T, averaged over tau: (s2 T² / tau²)(2x - 3 + 4e^-x - e^-2x), x = tau / T.
double MarkovAllanVariance(double s2, double T, double tau) {
  const double x = tau / T;
  if (x < 1e-4) return s2 * x / 3.0 * (1.0 - x / 4.0);  // series: avoids cancellation
  return s2 * (T * T / (tau * tau)) * (2.0 * x - 3.0 + 4.0 * std::exp(-x) - std::exp(-2.0 * x));
}

// SplitMix64's output function (a bijection of 64-bit words).
uint64_t Mix(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

// x rounded to the nearest integer (ties to even) for |x| < 2^52: adding and subtracting
// 2^52 of x's sign leaves no fraction bits. No library call, int64 cast or branch, so the
// loops below vectorise on baseline x86-64 (SSE2 has no double rounding instruction; GCC
// if-converts the selects with -fno-trapping-math, sim/CMakeLists.txt). Exact as long as the
// compiler keeps IEEE semantics (no -ffast-math, which would fold it to x).
inline double NearestInt(double x) {
  const double big = std::copysign(0x1p52, x);
  return (x + big) - big;
}

// floor(x) and trunc(x): with kRoundInstruction (the AVX2 loops, whose machines all have
// SSE4.1's rounding instruction) std::floor and std::trunc, one instruction each under
// -fno-trapping-math; otherwise emulated with NearestInt. Exact both ways, and + 0.0 turns the
// instruction's -0 (trunc of (-1, 0), floor of -0) into the emulation's +0: the same bytes.
// floor(x) for |x| < 2^52; from 2^52 on every double is already an integer, and inf or NaN
// (from an absurd gyro) passes through for the simulator's limits to refuse.
template <bool kRoundInstruction = false>
[[gnu::always_inline]] inline double Floor(double x) {
  if constexpr (kRoundInstruction) return std::floor(x) + 0.0;
  const double r = NearestInt(x);
  const double f = r - static_cast<double>(r > x);
  return std::abs(x) < 0x1p52 ? f : x;
}

// trunc(x) for |x| < 2^52 (the caller passes larger values by).
template <bool kRoundInstruction = false>
[[gnu::always_inline]] inline double Trunc(double x) {
  if constexpr (kRoundInstruction) return std::trunc(x) + 0.0;
  const double r = NearestInt(x);
  return r - std::copysign(static_cast<double>(std::abs(r) > std::abs(x)), x);
}

// The loops below vectorise; on x86-64 each is compiled for AVX2 and for SSE2 (sim/simd.h).

// y[k] += sigma z[k].
[[gnu::always_inline]] inline void AddScaledLoop(double* y, const double* z, double sigma, size_t n) {
  for (size_t k = 0; k < n; ++k) y[k] += sigma * z[k];
}

// A reading rounded half away from zero to a multiple of the resolution: truncate
// v / resolution + 0.5 v's sign. A multiple from 2^52 on has no fraction to round, and NaN
// passes through (the simulator's limits then refuse the run).
template <bool kRoundInstruction = false>
[[gnu::always_inline]] inline void RoundToResolutionLoop(double* v, size_t n, double resolution, double inv_resolution) {
  for (size_t k = 0; k < n; ++k) {
    const double scaled = v[k] * inv_resolution + std::copysign(0.5, v[k]);
    v[k] = std::abs(scaled) < 0x1p52 ? Trunc<kRoundInstruction>(scaled) * resolution : v[k];
  }
}

// Rates from pulse counts: z[k] = floor(z[k]) pulses, y[k] = (z[k] - z[k - 1]) q / dt with
// z[-1] = *pulses, which becomes z[n - 1].
template <bool kRoundInstruction = false>
[[gnu::always_inline]] inline void PulseRatesLoop(double* y, double* z, size_t n, double q_over_dt, double* pulses) {
  for (size_t k = 0; k < n; ++k) z[k] = Floor<kRoundInstruction>(z[k]);
  y[0] = (z[0] - *pulses) * q_over_dt;
  for (size_t k = 1; k < n; ++k) y[k] = (z[k] - z[k - 1]) * q_over_dt;
  *pulses = z[n - 1];
}

#if defined(RLG_AVX2_DISPATCH)
RLG_AVX2 void AddScaledAvx2(double* y, const double* z, double sigma, size_t n) { AddScaledLoop(y, z, sigma, n); }
RLG_AVX2 void RoundToResolutionAvx2(double* v, size_t n, double resolution, double inv_resolution) {
  RoundToResolutionLoop<true>(v, n, resolution, inv_resolution);
}
RLG_AVX2 void PulseRatesAvx2(double* y, double* z, size_t n, double q_over_dt, double* pulses) {
  PulseRatesLoop<true>(y, z, n, q_over_dt, pulses);
}
#endif

void AddScaled(double* y, const double* z, double sigma, size_t n) {
#if defined(RLG_AVX2_DISPATCH)
  if (UseAvx2()) return AddScaledAvx2(y, z, sigma, n);
#endif
  AddScaledLoop(y, z, sigma, n);
}

void RoundToResolution(double* v, size_t n, double resolution, double inv_resolution) {
#if defined(RLG_AVX2_DISPATCH)
  if (UseAvx2()) return RoundToResolutionAvx2(v, n, resolution, inv_resolution);
#endif
  RoundToResolutionLoop(v, n, resolution, inv_resolution);
}

void PulseRates(double* y, double* z, size_t n, double q_over_dt, double* pulses) {
#if defined(RLG_AVX2_DISPATCH)
  if (UseAvx2()) return PulseRatesAvx2(y, z, n, q_over_dt, pulses);
#endif
  PulseRatesLoop(y, z, n, q_over_dt, pulses);
}

}  // namespace

Rng::Rng(uint64_t seed, uint64_t stream, uint64_t substream) {
  // Each lane's 128-bit state is two outputs of SplitMix64 started at k: decorrelated streams
  // and substreams from one user seed (noise.h).
  uint64_t k = Mix(Mix(Mix(seed) ^ stream) ^ substream);
  auto next = [&k] { return Mix(k += 0x9E3779B97F4A7C15ULL); };
  using U128 = pcg64_fast::state_type;
  for (auto& lane : lanes_) {
    const uint64_t hi = next(), lo = next();
    lane = pcg64_fast((U128(hi) << 64) | lo);
  }
}

void Rng::Fill(double* out, size_t n) {
  while (n > 0) {
    if (next_ == kBlock && n >= kBlock) {  // a whole block: no copy
      Generate(out);
      out += kBlock;
      n -= kBlock;
      continue;
    }
    if (next_ == kBlock) {
      Generate(block_.data());
      next_ = 0;
    }
    const size_t m = std::min(n, kBlock - next_);
    std::copy_n(block_.data() + next_, m, out);
    next_ += m;
    out += m;
    n -= m;
  }
}

namespace {

using Table = boost::random::detail::normal_table<double>;  // X[0..128] decreasing to 0, Y = exp(-X²/2)

// r in [0, 1) from the 52 bits above bit 11: 1.r as a double's bits, minus 1 (exact). The
// same bit operations on two words at once are the SSE2 path of Rng::Generate.
constexpr uint64_t kOneBits = 0x3FF0000000000000ULL;
inline double Uniform52(uint64_t word) {
  const uint64_t bits = kOneBits | (word >> 12);
  double r;
  std::memcpy(&r, &bits, sizeof r);
  return r - 1.0;
}
// u in (0, 1] from the top 53 bits, for a logarithm.
inline double UniformOpen0(uint64_t word) { return static_cast<double>(static_cast<int64_t>(word >> 11) + 1) * 0x1p-53; }
// x with the sign of bit 7 of word: flipping the sign bit, not a branch (a coin toss that the
// branch predictor would miss half the time).
inline double WithSign(double x, uint64_t word) {
  uint64_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  bits ^= (word & 0x80) << 56;
  std::memcpy(&x, &bits, sizeof x);
  return x;
}

}  // namespace

void Rng::Generate(double* out) {
  // Candidate words, lane by lane in turn: the lanes live in registers and their multiplies
  // overlap.
  std::array<uint64_t, kBlock> words;
  std::array<pcg64_fast, kLanes> lanes = lanes_;
  for (size_t k = 0; k < kBlock; k += kLanes)
    for (int j = 0; j < kLanes; ++j) words[k + j] = lanes[j]();
  lanes_ = lanes;
  // The fast path, branch-free: x = r X[i] inside the layer's rectangle is the draw; the
  // others are listed and completed afterwards (their extra words come from lane 0).
  const double* const X = Table::table_x;
  std::array<uint16_t, kBlock> outside;
  size_t n_outside = 0;
  size_t k = 0;
#if defined(__SSE2__) && !defined(RLG_NO_SIMD)
  // Two words at a time, the very operations of the scalar loop below (bit operations, one
  // exact product, one compare), so both give the same bytes; baseline x86-64 has SSE2.
  const __m128i one_bits = _mm_set1_epi64x(static_cast<long long>(kOneBits)), sign_bit = _mm_set1_epi64x(0x80);
  const __m128d one = _mm_set1_pd(1.0);
  for (; k + 2 <= kBlock; k += 2) {
    const __m128i w = _mm_loadu_si128(reinterpret_cast<const __m128i*>(words.data() + k));
    const __m128d r = _mm_sub_pd(_mm_castsi128_pd(_mm_or_si128(_mm_srli_epi64(w, 12), one_bits)), one);
    const unsigned i0 = words[k] & 0x7F, i1 = words[k + 1] & 0x7F;
    const __m128d x = _mm_mul_pd(r, _mm_set_pd(X[i1], X[i0]));
    const __m128i sign = _mm_slli_epi64(_mm_and_si128(w, sign_bit), 56);
    _mm_storeu_pd(out + k, _mm_xor_pd(x, _mm_castsi128_pd(sign)));
    const int inside = _mm_movemask_pd(_mm_cmplt_pd(x, _mm_set_pd(X[i1 + 1], X[i0 + 1])));
    outside[n_outside] = static_cast<uint16_t>(k);
    n_outside += (inside & 1) ? 0 : 1;
    outside[n_outside] = static_cast<uint16_t>(k + 1);
    n_outside += (inside & 2) ? 0 : 1;
  }
#endif
  for (; k < kBlock; ++k) {
    const uint64_t w = words[k];
    const unsigned i = w & 0x7F;
    const double x = Uniform52(w) * X[i];
    out[k] = WithSign(x, w);
    outside[n_outside] = static_cast<uint16_t>(k);
    n_outside += x < X[i + 1] ? 0 : 1;
  }
  for (size_t j = 0; j < n_outside; ++j) out[outside[j]] = Complete(words[outside[j]]);
}

double Rng::Complete(uint64_t w) {
  const double* const X = Table::table_x;
  const double* const Y = Table::table_y;
  pcg64_fast& lane = lanes_[0];
  for (;;) {
    const unsigned i = w & 0x7F;
    const double x = Uniform52(w) * X[i];
    if (x < X[i + 1]) return WithSign(x, w);  // a fresh candidate inside its rectangle
    if (i == 0) {
      // Tail beyond r = X[1]: x = r + E1 / r, accepted when 2 E2 > (E1 / r)² (E exponential).
      const double r = X[1];
      for (;;) {
        const double e1 = -std::log(UniformOpen0(lane())) / r;
        const double e2 = -std::log(UniformOpen0(lane()));
        if (2.0 * e2 > e1 * e1) return WithSign(r + e1, w);
      }
    }
    // Wedge: (x, y) uniform in the layer's strip outside its rectangle; under the curve
    // exp(-x²/2) is a draw. Boost's bounds (normal_distribution.hpp, 1.56 on) decide most
    // points without exp: in a convex layer (X[i] >= 1) the curve lies between its tangent at
    // X[i] and the chord of the layer, in a concave one the other way round.
    const double y01 = Uniform52(lane());
    const double y = Y[i] + y01 * (Y[i + 1] - Y[i]);
    const double chord = (X[i] - X[i + 1]) * y01 - (X[i] - x);
    const double tangent = y - (Y[i] + (X[i] - x) * Y[i] * X[i]);
    const double above_upper = X[i] >= 1.0 ? chord : tangent;
    const double above_lower = X[i] >= 1.0 ? tangent : chord;
    if (above_upper < 0.0 && (above_lower < 0.0 || y < std::exp(-(x * x / 2.0)))) return WithSign(x, w);
    w = lane();
  }
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
  const double scale = kFlickerFloor * p.bias_instability_dph / mean_adev;
  for (auto& t : terms) t.second *= scale;
  return terms;
}

double GyroNoise::InstabilityAllanVariance(const GyroNoiseParams& params, double tau_s) {
  double avar = 0.0;
  for (const auto& [T, s] : InstabilityTerms(params)) avar += MarkovAllanVariance(s * s, T, tau_s);
  return avar;
}

GyroNoise::GyroNoise(const GyroNoiseParams& p, double dt_s, uint64_t seed, uint64_t stream)
    : arw_rng_(seed, stream, kSubstreamArw),
      instability_rng_(seed, stream, kSubstreamInstability),
      rrw_rng_(seed, stream, kSubstreamRrw),
      dt_(dt_s),
      white_sigma_(60.0 * p.arw_deg_per_sqrt_h / std::sqrt(dt_s)),
      rrw_sigma_(p.rrw_deg_per_h_per_sqrt_h * std::sqrt(dt_s) / 60.0),
      turn_on_(p.turn_on_sigma_dph > 0.0 ? p.turn_on_sigma_dph * instability_rng_.Normal() : 0.0),
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
    markov_.push_back({phi, sigma * std::sqrt(1.0 - phi * phi), sigma * instability_rng_.Normal(), ratio, ratio});  // stationary start
    instability_ += markov_.back().value;
    previous_every = every;
  }
  instability_draws_.resize(markov_.size() * kChunk);  // at most every term at every sample
}

void GyroNoise::Apply(double* rate_dph, size_t n) {
  for (size_t i = 0; i < n; i += kChunk) ApplyChunk(rate_dph + i, std::min(kChunk, n - i));
}

void GyroNoise::ApplyChunk(double* y, size_t n) {
  double* const z = scratch_.data();
  // The held instability terms and random walk enter each sample, then the due terms advance,
  // in order of increasing T (the order of their draws); the walk steps after the sample.
  // Members are copied to locals: stores through y could alias them, which would force a
  // reload of each after every sample.
  const bool rrw_on = rrw_sigma_ > 0.0;
  if (rrw_on) rrw_rng_.Fill(z, n);
  const double turn_on = turn_on_, rrw_sigma = rrw_sigma_;
  double rrw = rrw_, instability = instability_;
  Markov* const terms = markov_.data();
  const size_t n_terms = markov_.size();
  // The chunk's instability draws at once, in the order its updates take them (sample by
  // sample, by increasing T): how many, the countdowns alone tell. A term updates on the
  // left-th update of the one before it (sample, for the first) and every ratio-th after.
  size_t n_draws = 0;
  for (size_t j = 0, due = n; j < n_terms && due > 0; ++j) {
    const auto left = static_cast<size_t>(terms[j].left), ratio = static_cast<size_t>(terms[j].ratio);
    due = due >= left ? (due - left) / ratio + 1 : 0;
    n_draws += due;
  }
  double* const draws = instability_draws_.data();
  instability_rng_.Fill(draws, n_draws);
  size_t next_draw = 0;
  // The first term, the one that may update every sample, in a local: in the array its
  // countdown and value went through memory on the chain from one sample to the next (a store
  // through y may alias them). The others are due at most every third of its updates.
  auto samples = [&](auto has_terms) {
    Markov first = has_terms ? terms[0] : Markov{};
    for (size_t k = 0; k < n; ++k) {
      y[k] = y[k] + turn_on + rrw + instability;
      if (has_terms && --first.left == 0) {
        first.left = first.ratio;
        const double next = first.phi * first.value + first.drive * draws[next_draw++];
        instability += next - first.value;  // rounding drift ~1e-16 sqrt(updates) of a term: negligible
        first.value = next;
        for (size_t j = 1; j < n_terms; ++j) {
          Markov& m = terms[j];
          if (--m.left != 0) break;
          m.left = m.ratio;
          const double later = m.phi * m.value + m.drive * draws[next_draw++];
          instability += later - m.value;
          m.value = later;
        }
      }
      if (rrw_on) rrw += rrw_sigma * z[k];
    }
    if (has_terms) terms[0] = first;
  };
  if (n_terms > 0) {
    samples(std::true_type{});
  } else {
    samples(std::false_type{});
  }
  rrw_ = rrw;
  instability_ = instability;
  if (white_sigma_ > 0.0) {
    arw_rng_.Fill(z, n);
    AddScaled(y, z, white_sigma_, n);
  }
  if (q_ <= 0.0) return;
  // The angle is a running sum (serial); its pulse count and their differences vectorise.
  double angle = angle_arcsec_;
  const double dt = dt_, inv_q = inv_q_, q_over_dt = q_over_dt_;
  for (size_t k = 0; k < n; ++k) {
    angle += y[k] * dt;  // °/h x s = arcsec
    z[k] = angle * inv_q;
  }
  angle_arcsec_ = angle;
  PulseRates(y, z, n, q_over_dt, &pulses_);
}

void SensorNoise::ReadInPlace(double* T_C, size_t n, Rng& rng) const {
  constexpr size_t kChunk = Rng::kBlock;  // whole blocks go straight into z
  std::array<double, kChunk> z;
  const double sigma = sigma_, resolution = resolution_, inv_resolution = inv_resolution_;
  for (size_t i = 0; i < n; i += kChunk) {
    const size_t m = std::min(kChunk, n - i);
    double* const v = T_C + i;
    if (sigma > 0.0) {
      rng.Fill(z.data(), m);
      AddScaled(v, z.data(), sigma, m);
    }
    if (resolution > 0.0) RoundToResolution(v, m, resolution, inv_resolution);
  }
}

}  // namespace rlg::sim
