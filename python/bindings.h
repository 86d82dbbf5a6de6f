#pragma once
// The parts of the module, each defined in its own file and called by module.cpp.

#include <pybind11/pybind11.h>

namespace rlg::python {

namespace py = pybind11;

void BindGyro(py::module_& m);      // bind_diagnose.cpp: Gyro, load_gyro, save_gyro
void BindTrace(py::module_& m);     // bind_trace.cpp: Run, Trace, read_csv, write_csv, simulate
void BindFit(py::module_& m);       // bind_fit.cpp: fit, Compensator
void BindEvaluate(py::module_& m);  // bind_evaluate.cpp: evaluate, allan
void BindDiagnose(py::module_& m);  // bind_diagnose.cpp: diagnose
void BindPopulation(py::module_& m);  // bind_population.cpp: population_count, population_gyros, population_summary
void BindPlan(py::module_& m);        // bind_plan.cpp: plan, plan_count, plan_gyros, plan_merge

}  // namespace rlg::python
