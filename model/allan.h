#pragma once
/// Overlapping Allan deviation at octave-spaced averaging times, and the IEEE Std 952 noise
/// read-offs (conventions in ../shared/PHYSICS.md):
///   sigma²(tau) = 3 Q²/tau² + N²/tau + (0.664 B)² + K² tau / 3
/// with N the angle random walk, B the bias instability (flicker floor sigma = 0.664 B),
/// K the rate random walk and Q the quantization noise, in the units of the rate samples
/// and seconds. The terms are found by a non-negative weighted least-squares fit of that sum
/// to the measured Allan variance, which is the slope-line read-off done all at once.
///
/// Cost: O(n) per tau with a cumulative sum, O(n log n) in all.

#include <cstddef>
#include <string>
#include <vector>

namespace rlg::model {

struct AllanCurve {
  std::vector<double> tau_s;
  std::vector<double> adev;       ///< Allan deviation, units of the input samples
  std::vector<double> n_samples;  ///< number of overlapping differences per tau (for weights)
};

/// Overlapping Allan deviation of rate samples y taken every dt_s seconds, at tau = m dt_s,
/// m = 1, 2, 4, ... while at least `min_clusters` independent clusters fit in the record.
AllanCurve OverlappingAllan(const std::vector<double>& y, double dt_s, int min_clusters = 9);

struct NoiseTerms {
  double quantization = 0.0;      ///< Q (rate x s)
  double arw = 0.0;               ///< N (rate x sqrt(s)): sigma(1 s)
  double bias_instability = 0.0;  ///< B (rate)
  double rrw = 0.0;               ///< K (rate / sqrt(s))
};

/// The model's Allan variance at tau: 3 Q²/tau² + N²/tau + (0.664 B)² + K² tau / 3.
double AllanVariance(const NoiseTerms& terms, double tau_s);

/// Fits the four-term model to an Allan curve (each point weighted by its relative
/// uncertainty ~ 1/sqrt(n_samples)).
NoiseTerms FitNoiseTerms(const AllanCurve& curve);

/// The sample period a record is analysed at: the median of its time steps, so that a gap or
/// jittered time stamps do not shift it (the mean step over the record would). Blocks and
/// clusters are counted in samples of this period. InputError with fewer than two samples.
double SamplePeriod(const std::vector<double>& t_s);

/// "Bias stability" as the reports state it (SPEC section 3): the 1 sigma (n - 1) of the means
/// of consecutive, non-overlapping blocks, with the averaging time it was really computed at.
struct Stability {
  double sigma = 0.0;
  double averaging_s = 0.0;    ///< samples_per_block x dt: the time actually averaged
  double requested_s = 0.0;    ///< the time asked for
  size_t samples_per_block = 0;
  size_t blocks = 0;
  bool below_sample_period = false;  ///< asked for less than one sample: computed at one sample
  /// True when averaging_s differs from requested_s (rounded to whole samples, or raised to one).
  bool adjusted() const;
};

/// What to do with an averaging time shorter than one sample: refuse it (the user asked for it
/// explicitly) or compute at one sample (a default such as 1 s meeting coarser data).
enum class BelowSamplePeriod { kRefuse, kUseOneSample };

/// Blocks of m = round(tau_s / dt_s) samples (at least one). InputError when fewer than two
/// blocks fit, and, with kRefuse, when tau_s is shorter than dt_s.
Stability BiasStability(const std::vector<double>& y, double dt_s, double tau_s,
                        BelowSamplePeriod below = BelowSamplePeriod::kRefuse);

/// How a report names the averaging time of a stability: "1 s", "10 s (one sample: 1 s is
/// below the 10 s sample period)", "120 s (2 samples of 60 s: 100 s is not a whole number of
/// samples)".
std::string DescribeAveraging(const Stability& s, double dt_s);

/// Conversions for a rate in °/h and time in s to the customary gyro units.
inline double ArwDegPerSqrtHour(const NoiseTerms& t) { return t.arw / 60.0; }
inline double RrwDegPerHourPerSqrtHour(const NoiseTerms& t) { return t.rrw * 60.0; }

}  // namespace rlg::model
