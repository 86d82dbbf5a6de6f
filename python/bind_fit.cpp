// Eq. (2): fit and the causal Compensator (model/guo2006.h, compensation/compensator.h).

#include <fmt/format.h>
#include <optional>
#include <pybind11/stl.h>

#include "compensation/compensator.h"
#include "model/coefficients_json.h"
#include "python/bindings.h"
#include "python/convert.h"
#include "sim/errors.h"
#include "tools/rlgtherm/common.h"

namespace rlg::python {
namespace {

model::FitOptions::Method ParseMethod(const std::string& m) {
  if (m == "joint") return model::FitOptions::Method::kJoint;
  if (m == "two_stage") return model::FitOptions::Method::kTwoStage;
  throw InputError(fmt::format("method '{}': expected joint or two_stage", m));
}

py::dict Fit(const py::object& data, const std::array<std::string, 2>& pair, const std::string& method,
               const std::vector<std::string>& runs, double b0_window_s, double average_s) {
  const auto trace = TraceOf(data);
  model::FitOptions o;
  o.pair = pair;
  o.method = ParseMethod(method);
  o.b0_window_s = b0_window_s;
  nlohmann::json j;
  {
    py::gil_scoped_release release;
    // As `rlgtherm fit`: the chosen runs (copies of block means when average_s > 0, else the
    // runs in place), and a refusal about the data names the file it was read from.
    std::vector<const sim::Run*> selected = trace->Select(runs);
    std::vector<sim::Run> averaged;
    if (average_s > 0.0) {
      averaged = cli::Averaged(selected, average_s);
      selected = cli::Pointers(averaged);
    }
    auto fit = [&] { return model::FitGuo2006(selected, o); };
    j = model::ToJson(trace->source.empty() ? fit() : cli::NamingFile(trace->source, fit));
  }
  return ToPython(j);
}

/// The warning `rlgtherm compensate` prints for a run whose power-on Ti0 lies outside the
/// range of Ti0 the coefficients were fitted on (Eq. (2)'s quadratics in Ti0 extrapolate).
std::optional<std::string> OutsideFittedRange(const model::Guo2006Coefficients& c, double Ti0, const std::string& where) {
  if (Ti0 >= c.t10_range_C[0] && Ti0 <= c.t10_range_C[1]) return std::nullopt;
  return fmt::format("{}: Ti0 = {:.2f} °C is outside the fitted range {:.2f} ... {:.2f} °C", where, Ti0,
                     c.t10_range_C[0], c.t10_range_C[1]);
}

/// The C++ Compensator and the coefficients it was made from (it does not expose them). Warns
/// (UserWarning) once per run when the run's power-on Ti0 is outside the fitted range.
struct PyCompensator {
  explicit PyCompensator(const model::Guo2006Coefficients& c) : coefficients(c), compensator(c) {}
  model::Guo2006Coefficients coefficients;
  compensation::Compensator compensator;
  bool power_on_checked = false;

  void Reset() {
    compensator.Reset();
    power_on_checked = false;
  }
  /// Call with the GIL held, after samples were fed.
  void CheckPowerOn() {
    if (power_on_checked) return;
    power_on_checked = true;
    if (auto w = OutsideFittedRange(coefficients, compensator.Ti0(), "Compensator")) Warn({*w});
  }
};

using Array = py::array_t<double, py::array::c_style | py::array::forcecast>;

py::array_t<double> UpdateMany(PyCompensator& self, const Array& t_s, const Array& Ti, const Array& Tj,
                               const Array& bias_dph) {
  for (const auto* a : {&t_s, &Ti, &Tj, &bias_dph})
    if (a->ndim() != 1) throw py::value_error("update_many: expected 1-D arrays");
  const py::ssize_t n = t_s.size();
  if (Ti.size() != n || Tj.size() != n || bias_dph.size() != n) {
    throw InputError(fmt::format("update_many: t_s has {} values, Ti {}, Tj {}, bias_dph {}: expected equal lengths", n,
                                 Ti.size(), Tj.size(), bias_dph.size()));
  }
  std::vector<double> out(static_cast<size_t>(n));
  {
    py::gil_scoped_release release;  // the arrays are held by the caller's references
    const double *t = t_s.data(), *i = Ti.data(), *j = Tj.data(), *b = bias_dph.data();
    for (py::ssize_t k = 0; k < n; ++k) out[static_cast<size_t>(k)] = self.compensator.Update(t[k], i[k], j[k], b[k]);
  }
  if (n > 0) self.CheckPowerOn();
  return Adopt(std::move(out));
}

}  // namespace

void BindFit(py::module_& m) {
  m.def("fit", &Fit, py::arg("data"), py::arg("pair") = std::array<std::string, 2>{"T1", "T2"},
        py::arg("method") = "joint", py::arg("runs") = std::vector<std::string>{}, py::arg("b0_window_s") = 120.0,
        py::arg("average_s") = 0.0,
        R"(Fits the seed paper's Eq. (2) for the sensor pair (Ti, Tj), as `rlgtherm fit` does.

  B - B0 = a1 dT + a2 dT² + a3 (Tj - Ti),  dT = Ti - Ti0,  a_k = A_k0 + A_k1 Ti0 + A_k2 Ti0²
  (B in °/h, T in °C; B0 = mean bias over the first b0_window_s seconds of a run)

data: a Trace (used in place), a Run or list of Runs (copied), or a CSV path. pair: two
channel names.
method: "joint" (nine A_kl in one least squares) or "two_stage" (the paper's).
runs: run ids to fit on (default: all). average_s: fit on block means of this many seconds
(copies of the runs; 0: the samples as given, in place).
Returns the dict `rlgtherm fit -o` writes: model, pair, B0_window_s, A (3x3, A[k-1][l]),
A_stderr, A_stderr_dof, stderr_method, A_ci95_halfwidth (95 % confidence half-widths),
T10_range_C, condition_number, residual_rms_dph, method, runs. ValueError for bad input,
NumericalError when the data cannot identify the coefficients. Releases the GIL.)");

  py::class_<PyCompensator>(m, "Compensator", R"(Causal Eq. (2) compensation, sample by sample, as a gyro computer runs it.

At the first sample Ti0 = Ti; during the first B0 window B0 is the running mean of the bias,
then frozen; every sample: out = B - B0 - (a1 dT + a2 dT² + a3 (Tj - Ti)) in °/h.
Compensator(coefficients): a dict as fit() returns it, or a coefficients JSON file path.
A run whose Ti0 lies outside the Ti0 range the coefficients were fitted on (T10_range_C) is
extrapolated: a UserWarning says so at its first sample, as `rlgtherm compensate` warns.)")
      .def(py::init([](const py::object& c) { return PyCompensator(CoefficientsOf(c)); }), py::arg("coefficients"))
      .def("reset", [](PyCompensator& self) { self.Reset(); }, "forgets the run: the next sample is a power-on")
      .def("update",
           [](PyCompensator& self, double t_s, double Ti, double Tj, double bias_dph) {
             const double out = self.compensator.Update(t_s, Ti, Tj, bias_dph);
             self.CheckPowerOn();
             return out;
           },
           py::arg("t_s"), py::arg("Ti"), py::arg("Tj"), py::arg("bias_dph"),
           "compensated bias (°/h) of one sample: time since power-on (s), Ti and Tj (°C), bias (°/h); "
           "samples in time order")
      .def("update_many", &UpdateMany, py::arg("t_s"), py::arg("Ti"), py::arg("Tj"), py::arg("bias_dph"),
           "update() over arrays, continuing the current run (so chunks of a stream give the same values as one "
           "call); returns a new array (°/h). Float64 C-contiguous inputs are read in place, others converted. "
           "Releases the GIL.")
      .def("compensate_run",
           [](const PyCompensator& self, const sim::Run& run, const std::string& bias_column) {
             std::vector<double> out;
             {
               py::gil_scoped_release release;
               out = compensation::CompensateRun(self.coefficients, run, bias_column);
             }
             const std::string& Ti = self.coefficients.pair[0];
             if (run.Has(Ti) && !run.Column(Ti).empty()) {
               if (auto w = OutsideFittedRange(self.coefficients, run.Column(Ti).front(), run.Where())) Warn({*w});
             }
             return Adopt(std::move(out));
           },
           py::arg("run"), py::arg("bias_column") = "bias_dph",
           "a whole run compensated from its power-on (a fresh pass, as `rlgtherm compensate` does; this object's "
           "own state is untouched); returns a new array (°/h)")
      .def_property_readonly("Ti0", [](const PyCompensator& self) { return self.compensator.Ti0(); },
                             "Ti at power-on (°C)")
      .def_property_readonly("B0", [](const PyCompensator& self) { return self.compensator.B0(); },
                             "B0 so far (°/h): the running mean during the window, then frozen")
      .def_property_readonly("b0_frozen", [](const PyCompensator& self) { return self.compensator.b0_frozen(); },
                             "True once the B0 window has passed")
      .def_property_readonly("pair", [](const PyCompensator& self) { return py::make_tuple(self.coefficients.pair[0], self.coefficients.pair[1]); },
                             "(Ti, Tj) channel names")
      .def_property_readonly("coefficients", [](const PyCompensator& self) { return py::dict(ToPython(model::ToJson(self.coefficients))); },
                             "the coefficients as a dict (the keys of fit())");
}

}  // namespace rlg::python
