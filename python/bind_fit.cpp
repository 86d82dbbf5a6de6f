// The model family: fit any model, compare them all, the causal Compensator and its C code
// (model/fit_model.h, compensation/model_comparison.h, compensation/model_compensator.h,
// compensation/c_export.h).

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <pybind11/stl.h>

#include "compensation/c_export.h"
#include "compensation/model_comparison.h"
#include "compensation/model_compensator.h"
#include "io/error_context.h"
#include "model/coefficients_json.h"
#include "model/fit_model.h"
#include "python/bindings.h"
#include "python/convert.h"
#include "sim/errors.h"

namespace rlg::python {
namespace {

py::dict Fit(const py::object& data, const std::optional<std::array<std::string, 2>>& pair,
             const std::optional<std::string>& method, const std::vector<std::string>& runs, double b0_window_s,
             double average_s, const std::optional<std::string>& model, const std::optional<std::string>& channel,
             const std::optional<int>& order, const std::vector<std::string>& terms,
             const std::optional<std::string>& offset, const std::optional<double>& reference_C,
             const std::optional<std::string>& beyond_range) {
  const auto trace = TraceOf(data);
  model::FitRequest r;
  r.model = model.value_or("");
  r.pair = pair;
  r.method = method;
  r.b0_window_s = b0_window_s;
  r.channel = channel;
  r.order = order;
  r.terms = terms;
  r.offset = offset;
  r.reference_C = reference_C;
  r.beyond_range = beyond_range;
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    j = model::ModelToJson(model::FitRequested(trace->Select(runs), r, average_s, trace->source));  // as `rlgtherm fit`
  }
  return ToPython(j);
}

py::dict Compare(const py::object& data, const std::vector<std::string>& fit_runs, const std::string& channel,
                 const std::array<std::string, 2>& pair, double b0_window_s, double train_fraction) {
  const auto trace = TraceOf(data);
  compensation::ComparisonOptions o;
  o.fit_runs = fit_runs;
  o.channel = channel;
  o.pair = pair;
  o.b0_window_s = b0_window_s;
  o.train_fraction = train_fraction;
  compensation::Comparison c;
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    auto compare = [&] { return compensation::CompareModels(*trace, o); };
    c = trace->source.empty() ? compare() : io::NamingFile(trace->source, compare);
    j = compensation::ComparisonJson(c);
  }
  py::dict out = ToPython(j);
  // Beside the JSON's numbers, what `compare --plot` draws: each fitted model's held-out samples
  // (its first channel, °C, and its compensated bias, °/h), for rlgtherm.plot.heldout.
  const py::list models = out["models"];
  for (size_t k = 0; k < c.models.size(); ++k) {
    compensation::ComparedModel& m = c.models[k];
    if (!m.fitted) continue;
    py::dict d = models[k];
    d["heldout_channel"] = model::ModelChannels(*m.fitted).front();
    d["heldout_T"] = Adopt(std::move(m.heldout_T));
    d["heldout_compensated_dph"] = Adopt(std::move(m.heldout_residual));
  }
  return out;
}

/// The C++ compensator and the model it was made from (it does not expose it). Warns
/// (UserWarning) once per run, as `rlgtherm compensate` does, when the run leaves the range the
/// model was fitted on: Eq. (2) a Ti0 outside T10_range_C (its quadratics in Ti0 extrapolate),
/// a polynomial a sample outside range_C (held at the range's edge).
struct PyCompensator {
  explicit PyCompensator(const model::FittedModel& m) : model(m), compensator(m), check(compensator.channels()) {}
  model::FittedModel model;
  compensation::ModelCompensator compensator;
  SampleCheck check;  ///< refuses a sample that would spoil the run (NaN, time going back)
  bool started = false, warned = false;
  bool outside = false;  ///< a polynomial's sample outside its range since the last check

  void Reset() {
    compensator.Reset();
    check.Reset();
    started = warned = outside = false;
  }
  double Update(double t_s, const double* T, double bias_dph) {
    const double out = compensator.Update(t_s, T, bias_dph);
    outside = outside || compensator.OutsideFittedRange();
    return out;
  }
  /// Call with the GIL held, after samples were fed.
  void CheckRange(const std::string& where) {
    if (warned) return;
    if (const auto* c = std::get_if<model::Guo2006Coefficients>(&model)) {
      if (started) return;  // Eq. (2) is checked at power-on only
      started = true;
      const double Ti0 = compensator.Ti0().value_or(c->t10_range_C[0]);
      if (Ti0 >= c->t10_range_C[0] && Ti0 <= c->t10_range_C[1]) return;
      Warn({fmt::format("{}: Ti0 = {:.2f} °C is outside the fitted range {:.2f} ... {:.2f} °C", where, Ti0,
                        c->t10_range_C[0], c->t10_range_C[1])});
      warned = true;
    } else if (outside) {
      const auto& p = std::get<model::PolyModel>(model);
      Warn({fmt::format("{}: {} left the fitted range {:.2f} ... {:.2f} °C; the polynomial is held at its edge there",
                        where, p.spec.channel, p.spec.range_C[0], p.spec.range_C[1])});
      warned = true;
    }
  }
};

/// `rlgtherm export COEFFS --c DIR`: a path names the file in the code's first comment, as the
/// CLI does, so the same path gives the same bytes.
std::vector<std::string> ExportC(const py::object& coefficients, const py::object& dir, const std::string& precision,
                                 const std::string& prefix) {
  compensation::CExportOptions o;
  if (precision != "double" && precision != "float") {
    throw InputError(fmt::format("precision '{}': expected \"double\" or \"float\"", precision));
  }
  o.precision = precision == "float" ? compensation::CPrecision::kFloat : compensation::CPrecision::kDouble;
  o.prefix = prefix;
  std::string error;
  if (!o.IsValid(&error)) throw InputError(error);
  if (!py::isinstance<py::dict>(coefficients)) o.source = PathOf(coefficients);
  const model::FittedModel m = ModelOf(coefficients);
  const std::string path = PathOf(dir);
  py::gil_scoped_release release;
  return compensation::WriteC(m, path, o);
}

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// The values after t_s: one per channel of the model, then the bias.
void CheckCount(const PyCompensator& self, size_t given, const char* what) {
  const auto& ch = self.compensator.channels();
  if (given != ch.size() + 1) {
    throw InputError(fmt::format("{}: the model takes t_s, {}, bias_dph ({} values after t_s); got {}", what,
                                 fmt::join(ch, ", "), ch.size() + 1, given));
  }
}

double Update(PyCompensator& self, double t_s, const py::args& values) {
  CheckCount(self, values.size(), "update");
  std::vector<double> T;
  for (size_t i = 0; i + 1 < values.size(); ++i) T.push_back(values[i].cast<double>());
  const double bias = values[values.size() - 1].cast<double>();
  if (const std::string why = self.check.Problem(t_s, T.data(), bias); !why.empty()) {
    throw InputError(fmt::format("update: {}; the sample was not fed", why));
  }
  self.check.Accept(t_s);
  const double out = self.Update(t_s, T.data(), bias);
  self.CheckRange("Compensator");
  return out;
}

py::array_t<double> UpdateMany(PyCompensator& self, const Array& t_s, const py::args& values) {
  CheckCount(self, values.size(), "update_many");
  std::vector<Array> arrays;
  for (const auto& v : values) arrays.push_back(v.cast<Array>());
  if (t_s.ndim() != 1) throw py::value_error("update_many: expected 1-D arrays");
  for (const auto& a : arrays)
    if (a.ndim() != 1) throw py::value_error("update_many: expected 1-D arrays");
  const py::ssize_t n = t_s.size();
  std::vector<std::string> sizes;
  bool equal = true;
  for (const auto& a : arrays) {
    sizes.push_back(std::to_string(a.size()));
    equal = equal && a.size() == n;
  }
  if (!equal) {
    std::vector<std::string> names = self.compensator.channels();
    names.push_back("bias_dph");
    std::vector<std::string> parts;
    for (size_t i = 0; i < names.size(); ++i) parts.push_back(names[i] + " " + sizes[i]);
    throw InputError(fmt::format("update_many: t_s has {} values, {}: expected equal lengths", n, fmt::join(parts, ", ")));
  }
  std::vector<double> out(static_cast<size_t>(n));
  {
    py::gil_scoped_release release;  // the arrays are held by the caller's references
    const size_t channels = arrays.size() - 1;
    std::vector<double> T(channels);
    const double* t = t_s.data();
    const double* b = arrays.back().data();
    SampleCheck check = self.check;  // every sample checked before any is fed
    for (py::ssize_t k = 0; k < n; ++k) {
      for (size_t c = 0; c < channels; ++c) T[c] = arrays[c].data()[k];
      if (const std::string why = check.Problem(t[k], T.data(), b[k]); !why.empty()) {
        throw InputError(fmt::format("update_many: sample {}: {}; no sample of this call was fed", k, why));
      }
      check.Accept(t[k]);
    }
    self.check = check;
    for (py::ssize_t k = 0; k < n; ++k) {
      for (size_t c = 0; c < channels; ++c) T[c] = arrays[c].data()[k];
      out[static_cast<size_t>(k)] = self.Update(t[k], T.data(), b[k]);
    }
  }
  if (n > 0) self.CheckRange("Compensator");
  return Adopt(std::move(out));
}

/// Compensator.compensate_run: a whole run from its power-on, with the warning `rlgtherm compensate`
/// prints for it.
py::array_t<double> CompensateRun(const PyCompensator& self, const sim::Run& run, const std::string& bias_column) {
  std::vector<double> out;
  {
    py::gil_scoped_release release;
    out = compensation::CompensateRun(self.model, run, bias_column);
  }
  if (const auto* c = std::get_if<model::Guo2006Coefficients>(&self.model)) {
    if (run.Has(c->pair[0]) && !run.Column(c->pair[0]).empty()) {
      const double Ti0 = run.Column(c->pair[0]).front();
      if (Ti0 < c->t10_range_C[0] || Ti0 > c->t10_range_C[1]) {
        Warn({fmt::format("{}: Ti0 = {:.2f} °C is outside the fitted range {:.2f} ... {:.2f} °C", run.Where(), Ti0,
                          c->t10_range_C[0], c->t10_range_C[1])});
      }
    }
  } else if (const size_t n = compensation::SamplesOutsideFittedRange(self.model, run); n > 0) {
    Warn({compensation::OutsideRangeWarning(std::get<model::PolyModel>(self.model), run, n)});
  }
  return Adopt(std::move(out));
}

/// fit, compare and export_c: the model verbs.
void BindModelVerbs(py::module_& m) {
  m.def("fit", &Fit, py::arg("data"), py::arg("pair") = py::none(), py::arg("method") = py::none(),
        py::arg("runs") = std::vector<std::string>{}, py::arg("b0_window_s") = model::kB0Window_s, py::arg("average_s") = 0.0,
        py::kw_only(), py::arg("model") = py::none(), py::arg("channel") = py::none(), py::arg("order") = py::none(),
        py::arg("terms") = std::vector<std::string>{}, py::arg("offset") = py::none(),
        py::arg("reference_C") = py::none(), py::arg("beyond_range") = py::none(),
        R"doc(Fits a compensation model, as `rlgtherm fit` does (docs/data-format.md, "Coefficient file").

model: "guo2006" (the seed paper's Eq. (2); the default where the runs have T1 and T2, or a pair
is given), "poly" (the default otherwise), "px4", "ardupilot" or "auto".
  guo2006:  B - B0 = a1 dT + a2 dT² + a3 (Tj - Ti),  dT = Ti - Ti0,  a_k = A_k0 + A_k1 Ti0 + A_k2 Ti0²
            (B in °/h, T in °C; B0 = mean bias over the first b0_window_s seconds of a run);
            pair: two channel names (default ("T1", "T2")); method: "joint" (nine A_kl in one least
            squares, the default) or "two_stage" (the paper's)
  poly:     a polynomial of `order` (1-5, default 3) in `channel` (default "T1") about
            reference_C (default the middle of the fitted span); beyond_range "hold" (T clipped
            to the fitted range, the default) or "extrapolate"; offset "fitted" (a constant, the
            default) or "power_on" (bias minus B0, referred to the power-on temperature); terms:
            any of "rate", "hysteresis", "lag", "gradient" (or "gradient:T2"), or products such
            as "T1*(T2-T1)", "(T2-T1)^2", "rate(T2-T1)" (docs/data-format.md)
  px4, ardupilot: the cubic presets (channel, reference_C)
  auto:     order, offset and terms, products among them, selected on the training data by a
            stepwise search scored by leave-one-run-out cross-validation (terms: its library);
            it extrapolates beyond its range
data: a Trace (used in place), a Run or list of Runs (copied), or a CSV path.
runs: run ids to fit on (default: all). average_s: fit on block means of this many seconds
(copies of the runs; 0: the samples as given, in place).
Returns the dict `rlgtherm fit -o` writes for that model (Eq. (2): A, A_stderr, A_stderr_dof,
A_ci95_halfwidth, T10_range_C, ...; poly: channel, order, offset, reference_C, range_C, terms,
coefficients [{name, unit, value, stderr, dof, ci95_halfwidth}], ...). ValueError for bad input,
NumericalError when the data cannot identify the coefficients. Releases the GIL.)doc");

  m.def("compare", &Compare, py::arg("data"), py::arg("fit_runs") = std::vector<std::string>{},
        py::arg("channel") = "T1", py::arg("pair") = std::array<std::string, 2>{"T1", "T2"},
        py::arg("b0_window_s") = model::kB0Window_s, py::arg("train_fraction") = 0.7,
        R"(Fits every model on training data and scores each on held-out data, as `rlgtherm compare --json`.

fit_runs: the training runs (the others are scored whole); empty: each run's first
train_fraction of its duration is fitted and the rest scored. Returns the dict of `compare
--json`: split, training, heldout, models (each with "model" and its fit options, the training
and cross-validation RMS, the held-out Table 2 metrics and its coefficients file) and selected
(chosen on the training data alone). Beside those, each fitted model has numpy arrays of its
held-out samples, what `compare --plot` draws (rlgtherm.plot.heldout): heldout_T (its first
channel, heldout_channel, °C) and heldout_compensated_dph (°/h). Releases the GIL.)");

  m.def("export_c", &ExportC, py::arg("coefficients"), py::arg("dir"), py::arg("precision") = "double",
        py::arg("prefix") = "rlg_comp",
        R"(Writes any model's causal compensator as C99 code for the gyro's processor, as `rlgtherm export
COEFFS --c DIR` does (docs/firmware.md): DIR/<prefix>.h and DIR/<prefix>.c with the coefficients
as constants and the API <prefix>_state, <prefix>_init(s), <prefix>_update(s, t_s, T_C, bias_dph)
in `precision` "double" or "float". coefficients: a dict as fit() returns it, or a coefficients
JSON file path (then named in the files' first comment, as the CLI names it). DIR is created if
missing and written whole or not at all. Returns the two paths. ValueError for a bad model, prefix
or precision.)");
}

/// The Compensator class: causal compensation sample by sample.
void BindCompensator(py::module_& m) {
  py::class_<PyCompensator>(m, "Compensator", R"(Causal compensation with any model's coefficients, sample by sample, as a gyro computer runs it.

update(t_s, *temperatures, bias_dph): the temperatures of the model's channels (`.channels`) in
order: Eq. (2) takes (Ti, Tj); a polynomial its channel, then each gradient's channel. At the
first sample the run starts (Eq. (2): Ti0 = Ti); a power-on model's B0 is the running mean of the
bias over the first B0 window, then frozen. Returns the compensated bias in °/h.
Compensator(coefficients): a dict as fit() returns it, or a coefficients JSON file path.
A run that leaves the range the model was fitted on (Eq. (2): Ti0 outside T10_range_C; a
polynomial: its channel outside range_C) is extrapolated or clipped: a UserWarning says so
once per run, as `rlgtherm compensate` warns. A sample that a data file could not hold (a
non-finite or implausible value, e.g. kelvin) or whose time is not after the previous sample's
is refused (ValueError) and not fed: one NaN in the B0 window would spoil the whole run.)")
      .def(py::init([](const py::object& c) { return PyCompensator(ModelOf(c)); }), py::arg("coefficients"))
      .def("reset", [](PyCompensator& self) { self.Reset(); }, "forgets the run: the next sample is a power-on")
      .def("update", &Update, py::arg("t_s"),
           "compensated bias (°/h) of one sample: time since power-on (s), the temperatures of .channels (°C), "
           "bias (°/h); samples in time order")
      .def("update_many", &UpdateMany, py::arg("t_s"),
           "update() over arrays (t_s, one per channel, bias_dph), continuing the current run (so chunks of a "
           "stream give the same values as one call); returns a new array (°/h). Float64 C-contiguous inputs are "
           "read in place, others converted. Releases the GIL.")
      .def("compensate_run", &CompensateRun, py::arg("run"), py::arg("bias_column") = "bias_dph",
           "a whole run compensated from its power-on (a fresh pass, as `rlgtherm compensate` does; this object's "
           "own state is untouched); returns a new array (°/h)")
      .def_property_readonly("Ti0",
                             [](const PyCompensator& self) -> py::object {
                               const auto Ti0 = self.compensator.Ti0();
                               return Ti0 ? py::object(py::float_(*Ti0)) : py::object(py::none());
                             },
                             "Eq. (2): Ti at power-on (°C); None for other models")
      .def_property_readonly("B0", [](const PyCompensator& self) { return self.compensator.B0(); },
                             "B0 so far (°/h): the running mean during the window, then frozen (0 for a fitted offset)")
      .def_property_readonly("b0_frozen", [](const PyCompensator& self) { return self.compensator.b0_frozen(); },
                             "True once the B0 window has passed")
      .def_property_readonly("channels", [](const PyCompensator& self) { return self.compensator.channels(); },
                             "the temperature channels update() takes, in order")
      .def_property_readonly("pair",
                             [](const PyCompensator& self) -> py::object {
                               const auto* c = std::get_if<model::Guo2006Coefficients>(&self.model);
                               if (!c) return py::none();
                               return py::make_tuple(c->pair[0], c->pair[1]);
                             },
                             "Eq. (2): (Ti, Tj) channel names; None for other models")
      .def_property_readonly("coefficients", [](const PyCompensator& self) { return py::dict(ToPython(model::ModelToJson(self.model))); },
                             "the coefficients as a dict (the keys of fit())");
}

}  // namespace

void BindFit(py::module_& m) {
  BindModelVerbs(m);
  BindCompensator(m);
}

}  // namespace rlg::python
