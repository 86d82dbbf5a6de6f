// Scoring: evaluate (the Table 2 metrics, compensation/evaluation.h) and allan (model/allan.h).

#include <cmath>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <limits>
#include <optional>
#include <pybind11/stl.h>

#include "compensation/evaluation.h"
#include "compensation/model_compensator.h"
#include "model/allan.h"
#include "python/bindings.h"
#include "python/convert.h"
#include "sim/errors.h"
#include "sim/trace_limits.h"
#include "io/error_context.h"

namespace rlg::python {
namespace {

/// ValueError at the first value of `values` that is not finite: every metric of a series with
/// one NaN or inf would be NaN, which the JSON writes as null (the CLI's reader refuses such a
/// value in a file at its line).
void RequireFinite(const std::vector<double>& values, const std::string& what, const sim::Run& run) {
  for (size_t i = 0; i < values.size(); ++i) {
    if (!std::isfinite(values[i])) {
      throw InputError(fmt::format("{}: {}[{}] is {} (at t_s = {}): the metrics need finite values", run.Where(), what,
                                   i, values[i], i < run.t_s.size() ? fmt::format("{}", run.t_s[i]) : "?"));
    }
  }
}

/// What `compensate --json` reports for one run (EvaluationJson), for coefficients of any model
/// `fit` writes (Eq. (2), the polynomials with any terms, products, beyond_range, auto's).
/// Without coefficients the evaluation's Ti is `temperature`, B0's window `b0_window_s` and no
/// fitted range applies (outside_fitted_range None).
py::dict Evaluate(const sim::Run& run, const std::vector<double>& compensated, py::handle coefficients,
                    const std::string& bias_column, const std::string& temperature, std::optional<double> averaging_s,
                    std::optional<double> b0_window_s) {
  const bool have_coefficients = !coefficients.is_none();
  model::FittedModel m;
  if (have_coefficients) {
    m = ModelOf(coefficients);
  } else {
    model::Guo2006Coefficients c;
    c.pair = {temperature, temperature};
    c.t10_range_C = {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
    m = c;
  }
  auto* c = std::get_if<model::Guo2006Coefficients>(&m);
  auto* poly = std::get_if<model::PolyModel>(&m);
  // b0_window_s replaces the model's own window (a power-on offset's; a fitted offset has none).
  if (b0_window_s && c) c->b0_window_s = *b0_window_s;
  if (b0_window_s && poly && poly->spec.offset == model::OffsetRule::kPowerOn) poly->spec.b0_window_s = *b0_window_s;
  if (compensated.size() != run.size()) {
    throw InputError(fmt::format("{}: the compensated bias has {} values, the run {} samples", run.Where(),
                                 compensated.size(), run.size()));
  }
  RequireFinite(compensated, "compensated", run);
  RequireFinite(run.t_s, "t_s", run);
  std::vector<std::string> read{bias_column};
  for (const auto& ch : model::ModelChannels(m)) read.push_back(ch);
  for (const std::string& name : read) {
    if (run.Has(name)) RequireFinite(run.Column(name), name, run);
  }
  // What Run() and the CSV reader refuse (kelvin temperatures, 1e8 °/h, time going back), the
  // arrays refused too; the compensated bias is a bias column.
  if (const std::string why = sim::FindUnreadableValue(run); !why.empty()) throw InputError(fmt::format("{}: {}", run.Where(), why));
  const sim::ValueRange bias_range = sim::RangeOf("bias_dph", sim::TraceLimits{});
  for (size_t i = 0; i < compensated.size(); ++i) {
    if (const std::string why = sim::RangeProblem(bias_range, compensated[i]); !why.empty()) {
      throw InputError(fmt::format("{}: compensated[{}] = {} at t_s = {}: {}", run.Where(), i, compensated[i], run.t_s[i], why));
    }
  }
  compensation::EvaluationOptions o;
  o.averaging_s = averaging_s.value_or(1.0);
  o.averaging_explicit = averaging_s.has_value();  // as --averaging: below the sample period is an error
  o.bias_column = bias_column;
  if (b0_window_s) o.b0_window_s = *b0_window_s;
  nlohmann::json j;
  size_t outside = 0;
  {
    py::gil_scoped_release release;
    // A refusal names the run's file and line as the CLI's does (a run made in Python has none).
    auto evaluate = [&] {
      const compensation::RunEvaluation e = compensation::EvaluateRun(run, compensated, m, o);
      if (poly && e.outside_fitted_range) outside = compensation::SamplesOutsideFittedRange(m, run);
      return e;
    };
    j = compensation::EvaluationJson(run.source.empty() ? evaluate() : io::AtRun(run, evaluate));
  }
  if (!have_coefficients) {
    j["outside_fitted_range"] = nullptr;
  } else if (j.value("outside_fitted_range", false)) {
    // The warning `rlgtherm compensate` and `evaluate` print.
    Warn({c ? fmt::format("{}: Ti0 = {:.2f} °C is outside the fitted range {:.2f} ... {:.2f} °C", run.Where(),
                          run.Column(c->pair[0]).front(), c->t10_range_C[0], c->t10_range_C[1])
            : compensation::OutsideRangeWarning(*poly, run, outside)});
  }
  return ToPython(j);
}

/// The per-run object of `allan --json`: run, sample_period_s, tau_s, adev_dph and the read-offs.
py::dict Allan(const std::string& id, const std::vector<double>& t_s, const std::vector<double>& rate,
               const std::string& where) {
  if (t_s.size() != rate.size()) {
    throw InputError(fmt::format("{}: t_s has {} values, the rate {}", where, t_s.size(), rate.size()));
  }
  // The CLI's floor (cmd_model.cpp, RunAllan): 9 clusters of 2 samples.
  if (rate.size() < 18) throw InputError(fmt::format("{}: {} samples are too few for an Allan deviation", where, rate.size()));
  nlohmann::json j;
  model::AllanCurve curve;
  double dt = 0.0;
  {
    py::gil_scoped_release release;
    dt = model::SamplePeriod(t_s);
    curve = model::OverlappingAllan(rate, dt);
    j = {{"run", id}, {"sample_period_s", dt}};
    model::AddNoiseTermsJson(model::ReadNoiseTerms(curve), j);
  }
  py::dict out = ToPython(j);
  out["tau_s"] = Adopt(std::move(curve.tau_s));
  out["adev_dph"] = Adopt(std::move(curve.adev));
  return out;
}

/// A run holding only what EvaluateRun reads: t_s, the temperature and the raw bias (copies).
sim::Run ArraysRun(const std::string& id, py::handle t_s, py::handle bias, py::handle temperature,
                   const std::string& temperature_name) {
  sim::Run run;
  run.id = id;
  run.t_s = ToVector(t_s, "t_s");
  run.AddColumn(temperature_name) = ToVector(temperature, "temperature");
  run.AddColumn("bias_dph") = ToVector(bias, "bias");
  for (size_t c = 0; c < run.names.size(); ++c) {
    if (run.columns[c].size() != run.size()) {
      throw InputError(fmt::format("{}: {} has {} values, t_s {}", run.Where(), c == 0 ? "temperature" : "bias",
                                   run.columns[c].size(), run.size()));
    }
  }
  return run;
}

}  // namespace

void BindEvaluate(py::module_& m) {
  const char* evaluate_doc = R"(The Table 2 metrics of a compensated bias, per run, as `rlgtherm compensate --json`.

Two forms:
  evaluate(t_s, bias, compensated, temperature, *, coefficients=None, averaging_s=None,
           b0_window_s=None, run="run")            arrays (copied)
  evaluate(run, compensated, *, coefficients=None, bias_column="bias_dph", temperature="T1",
           averaging_s=None, b0_window_s=None)     a Run (read in place; compensated copied)
t_s in s; bias and compensated in °/h (any compensator's output: Eq. (2)'s or your own);
temperature: Ti in °C, the channel the trend is measured against (with coefficients of any
model fit writes, the model's first channel; the arrays form takes models of one channel). averaging_s: the first stability's averaging time (default 1 s, raised to one
sample on coarser data; given explicitly, below the sample period is a ValueError).
b0_window_s: the window whose mean error is b0_error_dph (default: the coefficients', else
120 s). Returns the dict of one run of `compensate --json`: bias_before_dph, bias_after_dph,
stability_before_dph, stability_after_dph, stability_100s_before_dph,
stability_100s_after_dph, sample_period_s, stability_averaging_s,
stability_100s_averaging_s, trend_dph_per_C, trend_stderr_dph_per_C, b0_error_dph,
outside_fitted_range (None without coefficients), the Allan read-offs of the compensated
bias (arw_deg_per_sqrt_h, bias_instability_dph, rrw_deg_per_h_per_sqrt_h, None when not
resolved, with not_resolved) and run. Non-finite numbers are None, as in the JSON.)";
  m.def(
      "evaluate",
      [](const sim::Run& run, const py::object& compensated, const py::object& coefficients, const std::string& bias_column,
         const std::string& temperature, std::optional<double> averaging_s, std::optional<double> b0_window_s) {
        return Evaluate(run, ToVector(compensated, "compensated"), coefficients, bias_column, temperature, averaging_s,
                        b0_window_s);
      },
      py::arg("run"), py::arg("compensated"), py::kw_only(), py::arg("coefficients") = py::none(),
      py::arg("bias_column") = "bias_dph", py::arg("temperature") = "T1", py::arg("averaging_s") = py::none(),
      py::arg("b0_window_s") = py::none(), evaluate_doc);
  m.def(
      "evaluate",
      [](const py::object& t_s, const py::object& bias, const py::object& compensated, const py::object& temperature, const py::object& coefficients,
         std::optional<double> averaging_s, std::optional<double> b0_window_s, const std::string& id) {
        std::string ti = "T1";
        if (!coefficients.is_none()) {
          // One temperature array: Eq. (2) is scored on its Ti alone (the trend, Ti0); a polynomial
          // that reads more channels needs them for its range and so a Run.
          const model::FittedModel m = ModelOf(coefficients);
          const auto channels = std::holds_alternative<model::Guo2006Coefficients>(m)
                                    ? std::vector<std::string>{model::ModelChannels(m).front()}
                                    : model::ModelChannels(m);
          if (channels.size() != 1) {
            throw InputError(fmt::format("evaluate: the model reads {} and the arrays form takes one temperature; "
                                         "pass a Run holding them",
                                         fmt::join(channels, ", ")));
          }
          ti = channels.front();
        }
        return Evaluate(ArraysRun(id, t_s, bias, temperature, ti), ToVector(compensated, "compensated"), coefficients,
                        "bias_dph", ti, averaging_s, b0_window_s);
      },
      py::arg("t_s"), py::arg("bias"), py::arg("compensated"), py::arg("temperature"), py::kw_only(),
      py::arg("coefficients") = py::none(), py::arg("averaging_s") = py::none(), py::arg("b0_window_s") = py::none(),
      py::arg("run") = "run");

  const char* allan_doc = R"(Overlapping Allan deviation and the IEEE Std 952 read-offs, as `rlgtherm allan --json`.

Two forms: allan(t_s, rate, *, run="run") (arrays, copied) and allan(run, column="bias_dph")
(a Run, read in place). t_s in s, rate in °/h (any column: raw, compensated, your own).
Returns the per-run dict of `allan --json`: run, sample_period_s (s), tau_s (s, array),
adev_dph (°/h, array), arw_deg_per_sqrt_h, bias_instability_dph, rrw_deg_per_h_per_sqrt_h
(None when the curve does not resolve the term) and not_resolved {term: {reason,
upper_bound}}. At least 18 samples.)";
  m.def(
      "allan",
      [](const sim::Run& run, const std::string& column) { return Allan(run.id, run.t_s, run.Column(column), run.Where()); },
      py::arg("run"), py::arg("column") = "bias_dph", allan_doc);
  m.def(
      "allan",
      [](const py::object& t_s, const py::object& rate, const std::string& id) {
        return Allan(id, ToVector(t_s, "t_s"), ToVector(rate, "rate"), fmt::format("run '{}'", id));
      },
      py::arg("t_s"), py::arg("rate"), py::kw_only(), py::arg("run") = "run");
}

}  // namespace rlg::python
