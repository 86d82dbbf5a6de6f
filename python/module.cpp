// import rlgtherm: the libraries' entry points for Python (docs/python.md).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "python/bindings.h"
#include "sim/errors.h"
#include "sim/simd.h"

PYBIND11_MODULE(_core, m) {  // rlgtherm._core, re-exported by python/rlgtherm/__init__.py
  namespace py = pybind11;
  using namespace rlg::python;
  m.doc() = R"(rlgtherm: simulate and compensate the thermal bias of ring laser gyroscopes.

Thin bindings over the C++ libraries the `rlgtherm` command runs (no science in Python):
simulate, read_csv, write_csv, fit, Compensator, evaluate, allan, diagnose, load_gyro,
save_gyro; population_gyros and population_summary for population suites. Units: time in s, temperatures in °C, bias in °/h, power in W. docs/python.md.

Errors: bad input raises ValueError with the message the CLI prints (exit status 2 there);
a numerical failure (solver, unidentifiable fit; exit status 3) raises rlgtherm.NumericalError,
an ArithmeticError; an output that cannot be written raises OSError.)";
  m.attr("__version__") = RLG_VERSION;  // CMakeLists.txt project(... VERSION)
#if defined(RLG_AVX2_DISPATCH)
  rlg::sim::UseAvx2();  // RLG_SIMD read now, under the GIL, before any thread of ours runs (sim/simd.h)
#endif

  // The classes, functions and NumericalError are made under the package's name, as a user names
  // them (rlgtherm.Trace in signatures, help(), tracebacks), not the private extension's:
  // pybind11 takes __module__ and the type names from the module's __name__, restored at the end.
  const py::object name = m.attr("__name__");
  m.attr("__name__") = "rlgtherm";

  // numpy's C API now, while the import holds the GIL. pybind11 2.10 looks it up on first use
  // into a function-local static (npy_api::get), and the lookup imports numpy, which releases
  // the GIL while it reads files: a second thread that then makes its first array holds the
  // GIL and waits on the static's guard, the first waits for the GIL, and neither ever runs
  // again (gdb: one thread in __cxa_guard_acquire under array_t's constructor, the other in
  // numpy's import waiting for the GIL). Done here, no call after import initialises anything
  // of numpy's (pybind11 2.12 makes the static GIL-safe; this is harmless there).
  py::dtype::of<double>();

  // Translators are tried last registered first: the one below takes InputError and
  // OutputError and passes NumericalError on to register_exception's.
  py::register_exception<rlg::NumericalError>(m, "NumericalError", PyExc_ArithmeticError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const rlg::InputError& e) {
      PyErr_SetString(PyExc_ValueError, e.what());
    } catch (const rlg::OutputError& e) {
      PyErr_SetString(PyExc_OSError, e.what());
    }
  });

  BindGyro(m);
  BindTrace(m);
  BindFit(m);
  BindEvaluate(m);
  BindDiagnose(m);
  BindPopulation(m);
  BindPlan(m);
  m.attr("__name__") = name;
}
