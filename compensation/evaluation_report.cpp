#include "compensation/evaluation_report.h"

#include <algorithm>
#include <fmt/format.h>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string_view>

#include "compensation/model_compensator.h"
#include "model/allan.h"
#include "sim/errors.h"

namespace rlg::compensation {

EvaluationReport EvaluateTrace(const sim::Trace& trace, const std::string& compensated_column,
                               const EvaluationOptions& options, const model::Guo2006Coefficients* coefficients) {
  EvaluationReport r;
  r.bias_column = options.bias_column;
  r.compensated_column = compensated_column;
  r.averaging_requested_s = options.averaging_s;
  r.title = coefficients ? fmt::format("Compensation of {} with pair ({}, {})", options.bias_column,
                                       coefficients->pair[0], coefficients->pair[1])
                         : fmt::format("Evaluation of {} against {} (trend against {})", compensated_column,
                                       options.bias_column, options.trend_channel);
  for (const auto& run : trace.runs) {
    try {
      const std::vector<double>& after = run.Column(compensated_column);
      r.runs.push_back(coefficients ? EvaluateRun(run, after, *coefficients, options)
                                    : EvaluateCompensated(run, after, options));
    } catch (const InputError& err) {
      // Every refusal names the file, the line of the run's first row and the run.
      const std::string where = run.Where();
      if (std::string_view(err.what()).rfind(where, 0) == 0) throw;
      throw InputError(fmt::format("{}: {}", where, err.what()));
    }
    const RunEvaluation& e = r.runs.back();
    if (e.outside_fitted_range) {
      r.warnings.push_back(fmt::format("{}: Ti0 = {:.2f} °C is outside the fitted range {:.2f} ... {:.2f} °C",
                                       run.Where(), e.Ti0_C, coefficients->t10_range_C[0],
                                       coefficients->t10_range_C[1]));
    }
  }
  return r;
}

EvaluationReport EvaluateTrace(const sim::Trace& trace, const std::string& compensated_column,
                               const EvaluationOptions& options, const model::FittedModel& model) {
  if (const auto* c = std::get_if<model::Guo2006Coefficients>(&model)) return EvaluateTrace(trace, compensated_column, options, c);
  const auto& p = std::get<model::PolyModel>(model);
  EvaluationOptions o = options;
  o.trend_channel = p.spec.channel;
  if (p.spec.offset == model::OffsetRule::kPowerOn) o.b0_window_s = p.spec.b0_window_s;
  EvaluationReport r = EvaluateTrace(trace, compensated_column, o);
  r.has_b0 = p.spec.offset == model::OffsetRule::kPowerOn;
  r.title = fmt::format("Compensation of {} with {}", options.bias_column, model::ModelTitle(model));
  for (size_t i = 0; i < trace.runs.size(); ++i) {
    const sim::Run& run = trace.runs[i];
    const size_t outside = SamplesOutsideFittedRange(model, run);
    r.runs[i].outside_fitted_range = outside > 0;
    if (outside > 0) {
      r.warnings.push_back(OutsideRangeWarning(p, run, outside));
    }
  }
  return r;
}

nlohmann::json EvaluationReportJson(const EvaluationReport& r) {
  const auto common = CommonAveraging(r.runs);
  nlohmann::json j;
  // The averaging time the stabilities were computed at (null when it differs between runs:
  // see each run's stability_averaging_s); the one asked for beside it.
  j["averaging_s"] = common ? nlohmann::json(*common) : nlohmann::json(nullptr);
  j["averaging_requested_s"] = r.averaging_requested_s;
  j["column"] = r.bias_column;
  j["compensated_column"] = r.compensated_column;
  j["runs"] = nlohmann::json::array();
  for (const auto& e : r.runs) j["runs"].push_back(EvaluationJson(e));
  return j;
}

std::string EvaluationReportText(const EvaluationReport& r) {
  const auto common = CommonAveraging(r.runs);
  const auto common100 = CommonAveraging(r.runs, true);
  fmt::memory_buffer out;
  auto line = std::back_inserter(out);
  fmt::format_to(line, "{}; bias stability = 1 sigma of consecutive {}\n", r.title,
                 common && common100 ? fmt::format("{:g} s and {:g} s means", *common, *common100)
                                     : "means, over the averaging times listed per run:");
  std::vector<std::string> notes;
  for (const auto& e : r.runs) {
    for (const auto* s : {&e.stability_after, &e.stability_100s_after}) {
      if (!s->adjusted() && common && common100) continue;
      const std::string note = (common && common100 ? "stability at " : e.run + ": stability at ") +
                               model::DescribeAveraging(*s, e.sample_period_s);
      if (std::find(notes.begin(), notes.end(), note) == notes.end()) notes.push_back(note);
    }
  }
  for (const auto& note : notes) fmt::format_to(line, "  {}\n", note);
  fmt::format_to(line, "{:<12} {:>9} {:>9} {:>9} {:>9} {:>10} {:>10} {:>16}{}\n", "run", "bias_bef", "bias_aft",
                 "stab_bef", "stab_aft", "stab100_b", "stab100_a", "trend °/h/°C", r.has_b0 ? fmt::format(" {:>9}", "B0 err") : "");
  for (const auto& e : r.runs) {
    fmt::format_to(line, "{:<12} {:>9.4f} {:>9.4f} {:>9.4f} {:>9.4f} {:>10.4f} {:>10.4f} {:>+9.4f}±{:<6.4f}{}\n",
                   e.run, e.bias_before_dph, e.bias_after_dph, e.stability_before.sigma, e.stability_after.sigma,
                   e.stability_100s_before.sigma, e.stability_100s_after.sigma, e.trend_dph_per_C,
                   e.trend_stderr_dph_per_C, r.has_b0 ? fmt::format(" {:>9.4f}", e.b0_error_dph) : "");
  }
  fmt::format_to(line, "\n{}", ReadOffsText(r.runs, 12));
  return fmt::to_string(out);
}

std::string ReadOffsText(const std::vector<RunEvaluation>& runs, size_t run_width) {
  fmt::memory_buffer out;
  auto line = std::back_inserter(out);
  fmt::format_to(line, "Allan read-offs of the compensated bias (IEEE 952; a term is read only where the curve shows it)\n");
  fmt::format_to(line, "{:<{}} {:>26} {:>26}\n", "run", run_width, "ARW °/√h", "bias instab. °/h");
  std::vector<std::string> ids;
  std::vector<model::NoiseReadOffs> readoffs;
  for (const auto& e : runs) {
    fmt::format_to(line, "{:<{}} {:>26} {:>26}\n", e.run, run_width, model::FormatReadOff(e.noise, model::NoiseTerm::kArw, 5),
                   model::FormatReadOff(e.noise, model::NoiseTerm::kBiasInstability, 5));
    ids.push_back(e.run);
    readoffs.push_back(e.noise);
  }
  for (const auto& note : model::NotResolvedNotes(ids, readoffs, {model::NoiseTerm::kArw, model::NoiseTerm::kBiasInstability})) {
    fmt::format_to(line, "  {}\n", note);
  }
  return fmt::to_string(out);
}

}  // namespace rlg::compensation
