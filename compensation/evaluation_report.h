#pragma once
/// The before/after table of a whole data file (the paper's Table 2 analogue), the one report
/// behind `rlgtherm compensate` (Eq. (2) applied here) and `rlgtherm evaluate` (a column some
/// other algorithm wrote): per run, compensation/evaluation.h's metrics of the compensated
/// column against the raw bias column, as JSON (the keys of `compensate --json`,
/// docs/data-format.md) or as the text table. The same trace, column and options give the same
/// numbers whichever verb asked.

#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "compensation/evaluation.h"
#include "model/compensation_model.h"
#include "model/guo2006.h"
#include "sim/trace.h"

namespace rlg::compensation {

struct EvaluationReport {
  std::string bias_column;         ///< the raw bias ("before"), °/h
  std::string compensated_column;  ///< the compensated bias ("after"), °/h
  double averaging_requested_s = 1.0;
  /// What produced the compensated column, for the text's first line: "Compensation of bias_dph
  /// with pair (T1, T2)", "Evaluation of my_dph against bias_dph (trend against T1)".
  std::string title;
  std::vector<RunEvaluation> runs;  ///< in file order
  /// One per run whose Ti0 lies outside the coefficients' T10_range_C (still evaluated).
  std::vector<std::string> warnings;
  /// Whether the compensation reads a B0 window (Eq. (2), a power-on offset, or no model): the
  /// text's "B0 err" column. A fitted offset has no B0, and the column is left out (the JSON
  /// keeps b0_error_dph, the error a B0 window of the default length would have).
  bool has_b0 = true;
};

/// Evaluates `compensated_column` against options.bias_column in every run of `trace`. With
/// coefficients (the fit that made the column), the trend channel and the B0 window are the
/// fit's and Ti0 is checked against its fitted range; without, options' trend_channel and
/// b0_window_s. InputError naming the run when a column is missing or a run is too short.
EvaluationReport EvaluateTrace(const sim::Trace& trace, const std::string& compensated_column,
                               const EvaluationOptions& options,
                               const model::Guo2006Coefficients* coefficients = nullptr);

/// The same for any model of the family (model/compensation_model.h): Eq. (2) exactly as above;
/// for a polynomial model the trend is regressed on its channel, the B0 error read at its B0
/// window (options' for a fitted offset), and a run is outside_fitted_range when its channel
/// leaves the fitted range anywhere (a warning says in how many samples: the polynomial is held
/// at the range's edge there).
EvaluationReport EvaluateTrace(const sim::Trace& trace, const std::string& compensated_column,
                               const EvaluationOptions& options, const model::FittedModel& model);

/// `compensate --json` / `evaluate --json`: {"averaging_s", "averaging_requested_s", "column",
/// "compensated_column", "runs": [EvaluationJson(run), ..]}. averaging_s is the averaging time
/// every run's stability was computed at, null when runs differ (mixed sample periods).
nlohmann::json EvaluationReportJson(const EvaluationReport& report);

/// The human summary: title, averaging times (with a note where one was adjusted to whole
/// samples), one row per run, then ReadOffsText of the runs.
std::string EvaluationReportText(const EvaluationReport& report);

/// The Allan read-offs of compensated runs as `validate`, `compensate` and `evaluate` print them:
/// a title line, a header, one row per run (ARW and bias instability, model::FormatReadOff) with
/// the run column `run_width` wide, then model::NotResolvedNotes, one per line, indented.
std::string ReadOffsText(const std::vector<RunEvaluation>& runs, size_t run_width);

}  // namespace rlg::compensation
