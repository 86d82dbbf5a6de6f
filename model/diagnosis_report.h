#pragma once
/// The report of a diagnosis: what `diagnose` prints and writes, as pure functions of a
/// `Diagnosis` (model/diagnose.h), so that the CLI, a future Python binding and the tests share
/// one definition and the CLI only parses, calls and prints.
///
/// Contract: nothing here re-runs or changes the diagnosis. Units as in the report: bias in °/h,
/// temperatures in °C, times in s; every RMS is a held-out RMS of score-block means
/// (Diagnosis::score_block_s), and a "ratio" is before over after, so > 1 is a gain.

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "model/diagnose.h"

namespace rlg::model {

/// The headline gain, `gain.heldout_rms_ratio` of the JSON report:
///   - 1 when no step was accepted (cause "none": the extended model is the baseline);
///   - when the first accepted step is a bias effect (and the data has a bias whose extended
///     held-out RMS is above 0): baseline bias RMS / extended bias RMS, the gain on the bias of
///     all accepted steps together;
///   - otherwise the first accepted step's own held-out RMS ratio (for a thermal effect, over
///     the temperature channels it was scored on).
double HeadlineRmsRatio(const Diagnosis& d);

/// `gain.compensated_stability_ratio`: the product over the accepted steps of each step's
/// stability ratio of the compensated bias (1 for a thermal step, 1 when none was accepted).
double CompensatedStabilityRatio(const Diagnosis& d);

/// The JSON report (`diagnose --json`, the report's diagnosis.json): cause, target, parameters
/// (of the first accepted step, or "none", "" and {}), baseline and extended metrics
/// (bias_rms_dph only with bias data), gain, candidates of the first search, accepted steps,
/// calibrated knobs, identifiability, parameter_correlations, ljung_box_p, score_block_s
/// ({min, max}) and notes. Keys are documented in docs/data-format.md.
nlohmann::json DiagnosisJson(const Diagnosis& d);

/// The averaging time of the report's RMS values, as computed: "100 s", or "99-100 s" when runs
/// of different sample periods hold different whole numbers of samples (three significant
/// digits).
std::string ScoreBlockText(const Diagnosis& d);

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
/// step with its parameters and held-out RMS before and after. Ends with a line break.
std::string DiagnosisText(const Diagnosis& d, const DiagnosisTextOptions& options);

}  // namespace rlg::model
