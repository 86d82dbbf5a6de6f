#pragma once
/// Overlapping Allan deviation at octave-spaced averaging times, and the IEEE Std 952 noise
/// read-offs (conventions in docs/physics.md):
///   sigma²(tau) = 3 Q²/tau² + N²/tau + (0.664 B)² + K² tau / 3
/// with N the angle random walk, B the bias instability (flicker floor sigma = 0.664 B),
/// K the rate random walk and Q the quantization noise, in the units of the rate samples
/// and seconds. The terms are found by a non-negative weighted least-squares fit of that sum
/// to the measured Allan variance, which is the slope-line read-off done all at once.
///
/// A fitted term is reported only when the measured curve shows it (ReadNoiseTerms). The
/// non-negative fit sets a term it cannot use to 0 and gives a term that only soaks up the
/// scatter of the last, few-cluster points some small value: neither is a measurement.
/// Resolved means: at some measured tau the term is the largest of the four contributions to
/// the fitted Allan variance AND its share of that variance is at least twice the relative
/// standard error of the measured point there. The first is the IEEE read-off's own premise
/// (a term is read on the stretch of the curve whose slope it sets: -1, -1/2, 0, +1/2); the
/// second keeps a term that leads only where the curve is too uncertain to tell (the longest
/// tau, ~9 clusters, ±45 % in variance) from being read there: without it, the model would
/// move by less than two standard errors of that point if the term were dropped. Because a
/// leading term must also outgrow its neighbours, a term invented by the fit from scatter
/// alone would need a point off by several standard errors to pass. Measured on simulated
/// noise, 200 seeds each: white noise over 2 h or 24 h never resolves B or K; the default
/// gyro's noise (N 0.001 °/sqrt(h), B 0.0035 °/h) resolves B in 197 of 200 records of 20 h
/// (mean 0.00346, sd 0.00029 °/h) and in none of 2 h, whose bound lies above 0.0035 in all 200.
/// An unresolved term comes with the reason and an upper bound from the measured curve: no
/// term can exceed the measured variance at any tau, so with each point's 2 sigma allowance
/// term(tau) <= avar(tau) (1 + 2 rel(tau)), at every tau.
///
/// Cost: O(n) per tau with a cumulative sum, O(n log n) in all.

#include <array>
#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

namespace rlg::model {

struct AllanCurve {
  std::vector<double> tau_s;
  std::vector<double> adev;       ///< Allan deviation, units of the input samples
  std::vector<double> n_samples;  ///< number of overlapping differences per tau (for weights)
};

/// Overlapping Allan deviation of rate samples y taken every dt_s seconds, at tau = m dt_s,
/// m = 1, 2, 4, ... while at least `min_clusters` independent clusters fit in the record, and
/// for at most `max_points` of these (the first: the same values).
AllanCurve OverlappingAllan(const std::vector<double>& y, double dt_s, int min_clusters = 9,
                            size_t max_points = std::numeric_limits<size_t>::max());

/// OverlappingAllan(y, dt_s, min_clusters) from `curve` = OverlappingAllan(y, dt_s, fewer) of
/// the same `samples` = y.size() with fewer <= min_clusters: its first points, the same values
/// (point i has m = 2^i), without a second pass over the record.
AllanCurve WithMinClusters(const AllanCurve& curve, size_t samples, int min_clusters);

/// 1 sigma relative error of the Allan variance at point i of the curve: sqrt(2 m / n) for
/// m samples per cluster and n overlapping differences (a slightly conservative form of the
/// overlapping estimator's equivalent degrees of freedom for white noise, ~3 n / 2 m).
double AllanVarianceRelativeError(const AllanCurve& curve, size_t i);

struct NoiseTerms {
  double quantization = 0.0;      ///< Q (rate x s)
  double arw = 0.0;               ///< N (rate x sqrt(s)): sigma(1 s)
  double bias_instability = 0.0;  ///< B (rate)
  double rrw = 0.0;               ///< K (rate / sqrt(s))
};

/// The model's Allan variance at tau: 3 Q²/tau² + N²/tau + (0.664 B)² + K² tau / 3.
double AllanVariance(const NoiseTerms& terms, double tau_s);

/// Fits the four-term model to an Allan curve (each point weighted by its relative
/// uncertainty ~ 1/sqrt(n_samples)). Every term the curve allows, resolved or not (the lowest
/// cost over all non-negative subsets): a variance model to extrapolate conservatively, not a
/// read-off (ReadNoiseTerms selects its terms by AIC).
NoiseTerms FitNoiseTerms(const AllanCurve& curve);

/// The four terms in the order of their Allan slopes (-1, -1/2, 0, +1/2).
enum class NoiseTerm { kQuantization = 0, kArw = 1, kBiasInstability = 2, kRrw = 3 };
const char* NoiseTermName(NoiseTerm term);  ///< "quantization", "ARW", ...

/// One term's read-off: its value when the curve resolves it; otherwise why not and what the
/// curve still allows.
struct TermReadOff {
  bool resolved = false;
  double value = 0.0;        ///< fitted value (units of NoiseTerms); a number only when resolved
  double upper_bound = 0.0;  ///< not resolved: the largest value the measured curve allows
  std::string reason;        ///< not resolved: why, in words (times in s)
};

/// The read-offs a report prints (see the header comment for "resolved").
struct NoiseReadOffs {
  NoiseTerms fitted;                 ///< the fit itself, every term (e.g. for AllanVariance)
  NoiseTerms every_term;             ///< FitNoiseTerms of the same curve (the same subset fits)
  std::array<TermReadOff, 4> terms;  ///< indexed by NoiseTerm
  double tau_min_s = 0.0, tau_max_s = 0.0;  ///< measured range (0 when the curve is empty)
  const TermReadOff& operator[](NoiseTerm t) const { return terms[static_cast<size_t>(t)]; }
};

NoiseReadOffs ReadNoiseTerms(const AllanCurve& curve);

/// Factor from the units of the samples (°/h, s) to the customary unit of a term's report:
/// ARW °/sqrt(h) (1/60), bias instability °/h (1), RRW °/h/sqrt(h) (60), quantization °/h s (1).
double ReportScale(NoiseTerm term);

/// A report's cell: "0.00098" (decimals given) or "not resolved (< 0.0071)".
std::string FormatReadOff(const NoiseReadOffs& r, NoiseTerm term, int decimals);

/// One line per distinct reason: "bias instability not resolved in fixed-30, fixed-20: <why>",
/// for the terms listed; runs[i] names readoffs[i].
std::vector<std::string> NotResolvedNotes(const std::vector<std::string>& runs, const std::vector<NoiseReadOffs>& readoffs,
                                          const std::vector<NoiseTerm>& terms);

/// The read-offs in the JSON of docs/cli.md: arw_deg_per_sqrt_h, bias_instability_dph,
/// rrw_deg_per_h_per_sqrt_h (null when not resolved) and "not_resolved": {key: {"reason",
/// "upper_bound"}} for the null ones, added to `out`. Rates in °/h, time in s.
void AddNoiseTermsJson(const NoiseReadOffs& r, nlohmann::json& out);

/// The sample period a record is analysed at: the median of its time steps, so that a gap or
/// jittered time stamps do not shift it (the mean step over the record would). Blocks and
/// clusters are counted in samples of this period. InputError with fewer than two samples.
double SamplePeriod(const std::vector<double>& t_s);

/// "Bias stability" as the reports state it (docs/cli.md): the 1 sigma (n - 1) of the means
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

/// The means of the consecutive blocks of m samples of y (a trailing partial block left out):
/// the means whose scatter BiasStability is (for m > 1).
std::vector<double> BlockMeans(const std::vector<double>& y, size_t m);

/// sim::Mean of two records of one length (a run's bias before and after compensation): the
/// same two values, their sums side by side. Each sum alone is one addition chain through the
/// record, as slow as the latency of an addition; two chains in one loop overlap.
std::array<double, 2> MeanPair(const std::vector<double>& a, const std::vector<double>& b);

/// BiasStability of two records of one length and sample period, the same two values, computed
/// side by side (as MeanPair). `block_means`, when given, receives each record's BlockMeans at
/// the blocks used (for blocks of one sample too). std::invalid_argument for records of
/// different lengths.
std::array<Stability, 2> BiasStabilityPair(const std::vector<double>& a, const std::vector<double>& b, double dt_s,
                                           double tau_s, BelowSamplePeriod below = BelowSamplePeriod::kRefuse,
                                           std::array<std::vector<double>, 2>* block_means = nullptr);

/// How a report names the averaging time of a stability: "1 s", "10 s (one sample: 1 s is
/// below the 10 s sample period)", "120 s (2 samples of 60 s: 100 s is not a whole number of
/// samples)".
std::string DescribeAveraging(const Stability& s, double dt_s);

/// Conversions for a rate in °/h and time in s to the customary gyro units.
inline double ArwDegPerSqrtHour(const NoiseTerms& t) { return t.arw / 60.0; }
inline double RrwDegPerHourPerSqrtHour(const NoiseTerms& t) { return t.rrw * 60.0; }

}  // namespace rlg::model
