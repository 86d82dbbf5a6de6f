// Gyro files (sim/gyro.h, sim/gyro_toml.h) and the diagnosis (diagnosis/diagnose.h, docs/diagnosis.md).

#include <fmt/format.h>
#include <pybind11/stl.h>
#include <sstream>

#include "diagnosis/diagnose.h"
#include "diagnosis/report.h"
#include "io/gyro_file.h"
#include "io/gyro_toml.h"
#include "python/bindings.h"
#include "python/convert.h"
#include "sim/errors.h"
#include "sim/gyro.h"

namespace rlg::python {
namespace {

/// diagnose()'s keyword options onto the library's (diagnosis/options.h documents each); an unknown
/// one is a TypeError, as for any Python function.
diagnosis::DiagnoseOptions Options(const py::kwargs& kwargs) {
  diagnosis::DiagnoseOptions o;
  for (const auto& [key, value] : kwargs) {
    const std::string k = py::str(key);
    if (k == "max_steps") o.max_steps = value.cast<int>();
    else if (k == "fit_runs") o.fit_runs = value.cast<std::vector<std::string>>();
    else if (k == "single_run_pieces") o.single_run_pieces = value.cast<int>();
    else if (k == "per_run_source_gains") o.per_run_source_gains = value.cast<bool>();
    else if (k == "power") o.power = value.cast<bool>();
    else if (k == "score_block_s") o.score_block_s = value.cast<double>();
    else if (k == "fit_block_s") o.fit_block_s = value.cast<double>();
    else if (k == "min_heldout_ratio") o.min_heldout_ratio = value.cast<double>();
    else if (k == "min_heldout_gain") o.min_heldout_gain = value.cast<double>();
    else if (k == "min_score") o.min_score = value.cast<double>();
    else if (k == "tie_score") o.tie_score = value.cast<double>();
    else if (k == "null_replicates") o.null_replicates = value.cast<int>();
    else if (k == "thermal_refits") o.thermal_refits = value.cast<int>();
    else if (k == "lookahead") o.lookahead = value.cast<int>();
    else throw py::type_error(fmt::format("diagnose() got an unexpected keyword argument '{}'", k));
  }
  return o;
}

}  // namespace

void BindGyro(py::module_& m) {
  py::class_<sim::GyroConfig>(m, "Gyro", R"(A gyro: thermal network, sensors, bias physics, noise and catalog effects.

Made by load_gyro(path); saved by save_gyro(gyro, path); to_toml() gives the file's text.
The file format is documented in scenarios/README.md ("Gyro file").)")
      .def_property_readonly("name", [](const sim::GyroConfig& g) { return g.name; })
      .def_property_readonly("channels",
                             [](const sim::GyroConfig& g) {
                               std::vector<std::string> out;
                               for (const auto& s : g.sensors) out.push_back(s.channel);
                               return out;
                             },
                             "sensor channels (T1, T2, ...) in output order")
      .def_property_readonly("effects",
                             [](const sim::GyroConfig& g) {
                               py::list out;
                               for (const auto& e : g.effects) {
                                 out.append(py::dict(py::arg("name") = e.name, py::arg("target") = e.target,
                                                     py::arg("parameters") = e.parameters));
                               }
                               return out;
                             },
                             "catalog effects applied, as [{name, target, parameters}]")
      .def("to_toml",
           [](const sim::GyroConfig& g) {
             std::ostringstream out;
             io::WriteGyroToml(g, out);
             return out.str();
           },
           "the gyro file's text (what save_gyro writes)")
      .def("__repr__", [](const sim::GyroConfig& g) {
        return fmt::format("<rlgtherm.Gyro '{}': {} nodes, {} sensors, {} effects>", g.name, g.network.nodes.size(),
                           g.sensors.size(), g.effects.size());
      });

  m.def("load_gyro", [](const py::object& path) { return io::LoadGyro(PathOf(path)); }, py::arg("path"),
        "Loads and checks a gyro TOML file (ValueError naming the file and line).");
  m.def("save_gyro", [](const sim::GyroConfig& g, const py::object& path) { io::SaveGyro(g, PathOf(path)); }, py::arg("gyro"),
        py::arg("path"),
        "Writes a gyro file that load_gyro reads back to the same gyro, whole or not at all "
        "(ValueError for what the format cannot say).");
}

void BindDiagnose(py::module_& m) {
  m.def(
      "diagnose",
      [](const py::object& data, const py::object& gyro, const py::kwargs& kwargs) {
        const auto trace = TraceOf(data, /*require_bias=*/false);
        const diagnosis::DiagnoseOptions o = Options(kwargs);
        nlohmann::json j;
        if (gyro.is_none()) {
          py::gil_scoped_release release;
          j = diagnosis::DiagnosisJson(diagnosis::DiagnoseWithoutNetwork(*trace, o));
        } else {
          sim::GyroConfig loaded;
          const sim::GyroConfig& nominal = GyroOf(gyro, loaded);
          py::gil_scoped_release release;
          j = diagnosis::DiagnosisJson(diagnosis::Diagnose(*trace, nominal, o));
        }
        return py::dict(ToPython(j));
      },
      py::arg("data"), py::arg("gyro") = py::none(),
      R"(Calibrates a nominal gyro to data and names what it misses, as `rlgtherm diagnose --json`.

data: a Trace (used in place), a Run or list of Runs (copied), or a CSV path; bias_dph
optional (thermal-only data).
gyro: a Gyro or the path of a gyro TOML file; None (the default) for data without a thermal
network, as `diagnose` without --gyro: the bias search alone over the measured channels (the
model family's polynomial baseline, the bias terms of the catalog; bias_dph required).
Options (keywords, diagnosis/options.h DiagnoseOptions): max_steps=3, fit_runs=[] (runs to fit
on; the others are held out), single_run_pieces=4, per_run_source_gains=False, power=False
(the report's `power`: each first-search candidate's 90 % sizes, as `--power`),
score_block_s=100, fit_block_s=10 (s), min_heldout_gain=0,
min_heldout_ratio=1.05 (without a gyro), min_score=10, tie_score=1e-6, null_replicates=40,
thermal_refits=4, lookahead=2 (thermal candidates tied in score compared one step ahead; 1: none;
unused without a gyro).
Returns the report of docs/diagnosis.md as a dict with the keys of `diagnose --json` (cause,
target, parameters, baseline, extended, gain, candidates, accepted, calibrated, calibration,
identifiability, ...; docs/data-format.md): bias in °/h, temperatures in °C, times in s.
Takes seconds to minutes; releases the GIL.)");
}

}  // namespace rlg::python
