#pragma once
/// The report of a diagnosis: what `diagnose` prints and writes, as pure functions of its
/// record (diagnose.h: a `Diagnosis` against a gyro, a `DiagnosisWithoutNetwork`, and the
/// `SearchRecord` both hold), so that the CLI, the Python module and the tests share one
/// definition and the CLI only parses, calls and prints.
///
/// Contract: nothing here re-runs or changes the diagnosis. Units as in the report: bias in °/h,
/// temperatures in °C, times in s; every RMS is a held-out RMS of score-block means
/// (Diagnosis::score_block_s), and a "ratio" is before over after, so > 1 is a gain.

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "diagnosis/diagnose.h"
#include "sim/effect.h"
#include "sim/gyro.h"

namespace rlg::diagnosis {

/// The headline gain, `gain.heldout_rms_ratio` of the JSON report:
///   - 1 when no step was accepted (cause "none": the extended model is the baseline);
///   - when the first accepted step is a bias effect (and the data has a bias whose extended
///     held-out RMS is above 0): baseline bias RMS / extended bias RMS, the gain on the bias of
///     all accepted steps together;
///   - otherwise the first accepted step's own held-out RMS ratio (for a thermal effect, over
///     the temperature channels it was scored on).
double HeadlineRmsRatio(const SearchRecord& d);

/// Whether what a diagnosis without a network leaves is at the noise: RmsOverNoise at most
/// kAllClearRmsOverNoise. Its verdict is an all-clear only then.
bool LeftAtNoise(const BiasLeft& left);

/// "the held-out residual is 0.0845 °/h RMS on 100 s means, 42.2x the white noise of such a
/// mean (0.002 °/h)": the text's `left:` line and the verdict's words for it.
std::string LeftText(const BiasLeft& left, const std::string& score_block);

/// The parameters of a candidate outside its effect's physically plausible range (the
/// catalog's, sim/effect.h); empty when plausible. The JSON's accepted[].plausible is
/// whether this is empty, and accepted[].implausible lists them.
std::vector<sim::RangeViolation> OutsidePlausibleRange(const Candidate& c);

/// The text's line for an implausible candidate: which parameters, their plausible ranges and
/// sources, and that either the data leave it unbounded there or the cause is a stand-in;
/// empty when plausible.
std::string StandInText(const Candidate& c);

/// `gain.compensated_stability_ratio`: the product over the accepted steps of each step's
/// stability ratio of the compensated bias (1 for a thermal step, 1 when none was accepted).
double CompensatedStabilityRatio(const SearchRecord& d);

/// The JSON report (`diagnose --json`, the report's diagnosis.json): cause, target, parameters
/// (of the first accepted step, or "none", "" and {}), baseline and extended metrics
/// (bias_rms_dph only with bias data), gain, candidates of the first search, accepted steps,
/// calibrated knobs, calibration (CalibrationJson), identifiability (the text's lines) and
/// identifiability_directions (IdentifiabilityJson), detected_steps ({run, t_s, size_dph,
/// statistic, threshold}), parameter_correlations, ljung_box_p, null_bootstrap ({threshold,
/// replicate_scores}), score_block_s ({min, max}) and notes. Keys are documented in
/// docs/data-format.md. Without a network the calibration's keys are there, empty, and `left`
/// says what is left in the bias.
nlohmann::json DiagnosisJson(const Diagnosis& d);
nlohmann::json DiagnosisJson(const DiagnosisWithoutNetwork& d);

/// The calibration's health (docs/diagnosis.md `calibration`): usable, cost {initial, final},
/// iterations, prior_sd, knobs [{name, nominal, calibrated, shift_sigma, posterior_sd}] and
/// prior_conflicts (knob names beyond kPriorConflictSigma).
nlohmann::json CalibrationJson(const CalibrationSummary& c);

/// Identifiability as data: knobs, determined, prior_sd, undetermined [{sd_ratio, loadings
/// [{knob, loading}] (every knob, largest first), reason}].
nlohmann::json IdentifiabilityJson(const Identifiability& id);

/// The text's calibration line: the `n` knobs moved furthest from nominal (value, nominal,
/// shift in prior sd) and the prior conflicts, or "none".
std::string CalibrationLine(const CalibrationSummary& c, size_t n = 3);

/// The averaging time of the report's RMS values, as computed: "100 s", or "99-100 s" when runs
/// of different sample periods hold different whole numbers of samples (three significant
/// digits).
std::string ScoreBlockText(const SearchRecord& d);

/// The knob pairs whose posterior correlation (log units) is at least `min_abs` in size,
/// strongest first (equal sizes in text order), at most `n`, as "C:block ~ G:block-ambient +0.93".
std::vector<std::string> StrongCorrelations(const Diagnosis& d, double min_abs, size_t n);

struct DiagnosisTextOptions {
  std::string data_name;  ///< the data file as the user named it, on the first line
  std::string gyro_name;  ///< the nominal gyro file as the user named it
  double min_correlation = 0.8;  ///< posterior correlations listed: |r| at least this,
  size_t max_correlations = 5;   ///< at most this many, strongest first
  size_t max_candidates = 8;     ///< candidates of the first search listed, best first
};

/// The human summary `diagnose` prints: baseline RMS, residual whiteness, identifiability,
/// strong posterior correlations and notes; the first search's best candidates; each accepted
/// step with its parameters and held-out RMS before and after. Ends with a line break. Without a
/// thermal network its first lines say so and name the baseline polynomial (BaselineName)
/// instead of the gyro file and the calibrated nominal.
std::string DiagnosisText(const Diagnosis& d, const DiagnosisTextOptions& options);
std::string DiagnosisText(const DiagnosisWithoutNetwork& d, const DiagnosisTextOptions& options);
/// The text's last line, after "verdict: ": what was added (stand-ins marked) and whether the
/// final model explains the data to the noise or leaves something unexplained. Without a
/// thermal network: "<baseline> misses <cause> on <target> (<parameters>; held-out RMS ratio
/// r)", or "unexplained: ..." with where the residual stands out and its correlations, or
/// "none: ...".
std::string DiagnosisVerdict(const Diagnosis& d);
std::string DiagnosisVerdict(const DiagnosisWithoutNetwork& d);

/// What the extensions were added to: "the calibrated nominal model", or without a thermal
/// network "the best polynomial in T1 (order 2)".
std::string BaselineName(const Diagnosis& d);
std::string BaselineName(const DiagnosisWithoutNetwork& d);

/// dT/dt (°C/min) of block means T at times t (s): central differences (T[i+1] - T[i-1]) /
/// (t[i+1] - t[i-1]), one-sided at the ends; exact on a linear ramp. All NaN with fewer than two
/// values. Precondition: t strictly increasing, t.size() >= T.size().
std::vector<double> RatePerMinute(const std::vector<double>& t, const std::vector<double>& T);

/// Means of consecutive full groups of g >= 1 values; a shorter remainder is left out (it would
/// be a noisier point than the others, and diagnose's score blocks leave it out too).
std::vector<double> GroupMeans(const std::vector<double>& v, size_t g);

/// The channel whose temperature the bias residuals are shown against: the sensor on the bias
/// node (T1, block, in the default gyro), else the first sensor. Precondition: a sensor exists.
std::string BiasTemperatureChannel(const sim::GyroConfig& gyro);

/// One column of residuals.csv after run and t_s.
struct ResidualColumn {
  enum class Kind {
    kMeasured,  ///< measured_<ch>: block means of the data (°C, or °/h for bias_dph)
    kRate,      ///< dTdt_<ch>_C_per_min: RatePerMinute of the measured block means (temperatures only)
    kBaseline,  ///< baseline_<ch>: measured - simulated by the calibrated nominal model
    kExtended,  ///< extended_<ch>: measured - simulated by the extended model
  };
  std::string name;
  std::string channel;  ///< "T1".., or "bias_dph"
  Kind kind;
};

/// One run's rows of residuals.csv.
struct ResidualTableRun {
  std::string run;
  std::vector<double> t_s;  ///< fit-block mid-times, one row each
  /// values[c][k]: column c at t_s[k]. A column is shorter than t_s (empty when the run lacks
  /// its channel, e.g. a run without bias) and its cells past the end are absent.
  std::vector<std::vector<double>> values;
};

/// residuals.csv of `diagnose --report`: per fit block of every run, per channel (the channels
/// of the first run's residuals, in name order) the data, for temperature channels its rate,
/// and the baseline and extended residuals of the channels some run has them of (every one
/// against a gyro; without a thermal network the bias alone, the temperatures being data only).
/// Bias residuals are held-out ones, each run with its own offset (ResidualTrace).
struct ResidualTable {
  std::vector<ResidualColumn> columns;
  std::vector<ResidualTableRun> runs;
};
ResidualTable MakeResidualTable(const SearchRecord& d);

/// What the report figure of one channel shows for one run.
struct ChannelFigureRun {
  std::string run;
  /// Fit blocks (n of them): mid-times (s), block means of the data, and the simulations of the
  /// calibrated nominal and the extended models (data - residual).
  std::vector<double> t_s, measured, simulated_baseline, simulated_extended;
  /// Fit blocks per score block (>= 1): the residual panels show means over groups of this many
  /// (GroupMeans), what diagnose scores; fit-block residuals are dominated by noise.
  size_t blocks_per_score_block = 1;
  /// Score-block means of the baseline and extended residuals, of the temperature the channel
  /// is shown against (°C) and of its rate (°C/min, RatePerMinute of the fit blocks).
  std::vector<double> residual_baseline, residual_extended, temperature_C, rate_C_per_min;
};

/// What the report figure of one channel shows (tools/rlgtherm/report_figures.h draws it).
struct ChannelFigure {
  std::string channel;      ///< "T1".., or "bias_dph"
  /// The channel the residuals are shown against: its own, for the bias the one given.
  std::string temperature;
  std::vector<ChannelFigureRun> runs;  ///< the runs that have the channel and that temperature
};

struct DiagnosisFigures {
  double score_block_s = 0.0;  ///< the longest score block (Diagnosis::score_block_s.second)
  bool extended = false;       ///< a step was accepted: the extended model is shown too
  /// One per channel of the ResidualTable with residuals, in its order (without a thermal
  /// network, the bias alone).
  std::vector<ChannelFigure> channels;
};

/// The figures' data; the bias residuals are shown against `bias_temperature`
/// (BiasTemperatureChannel of the nominal gyro).
DiagnosisFigures MakeDiagnosisFigures(const SearchRecord& d, const std::string& bias_temperature);

}  // namespace rlg::diagnosis
