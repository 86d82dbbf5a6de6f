// Data: Run, Trace, read_csv, write_csv, simulate (docs/data-format.md, docs/python.md).

#include <fmt/format.h>
#include <limits>
#include <sstream>
#include <pybind11/stl.h>

#include "io/atomic_output.h"
#include "io/csv.h"
#include "io/import.h"
#include "io/scenario_file.h"
#include "python/bindings.h"
#include "python/convert.h"
#include "python/interrupt.h"
#include "sim/errors.h"
#include "sim/gyro.h"
#include "sim/scenario.h"
#include "sim/simulator.h"

namespace rlg::python {
namespace {

/// A run made in Python: every column copied into the run (the libraries store vectors), then
/// checked as the CSV reader checks a file's values (io/csv.h, FindUnreadableValue).
sim::Run MakeRun(const std::string& id, const py::dict& columns) {
  sim::Run run;
  run.id = id;
  bool has_time = false;
  for (const auto& [key, values] : columns) {
    const std::string name = py::str(key);
    std::vector<double> v = ToVector(values, fmt::format("run '{}' column '{}'", id, name));
    if (name == "t_s") {
      run.t_s = std::move(v);
      has_time = true;
    } else {
      run.names.push_back(name);
      run.columns.push_back(std::move(v));
    }
  }
  if (!has_time) throw InputError(fmt::format("run '{}': no column 't_s' (time since power-on, s)", id));
  for (size_t c = 0; c < run.names.size(); ++c) {
    if (run.columns[c].size() != run.size()) {
      throw InputError(fmt::format("run '{}': column '{}' has {} values, t_s has {}", id, run.names[c],
                                   run.columns[c].size(), run.size()));
    }
  }
  if (const std::string why = sim::FindUnreadableValue(run); !why.empty()) {
    throw InputError(fmt::format("{}: {}", run.Where(), why));
  }
  return run;
}

/// `values` appended to `run` as column `name`, checked as MakeRun checks columns; the run is
/// left as it was on a refusal. Views of the other columns stay valid (Run::AddColumn).
void AddColumn(sim::Run& run, const std::string& name, const py::object& values) {
  if (name == "t_s" || run.Has(name)) throw InputError(fmt::format("{} already has a column '{}'", run.Where(), name));
  std::vector<double> v = ToVector(values, fmt::format("{} column '{}'", run.Where(), name));
  if (v.size() != run.size()) {
    throw InputError(fmt::format("{}: column '{}' has {} values, the run has {} samples", run.Where(), name, v.size(),
                                 run.size()));
  }
  run.AddColumn(name) = std::move(v);
  if (const std::string why = sim::FindUnreadableValue(run); !why.empty()) {
    run.names.pop_back();
    run.columns.pop_back();
    throw InputError(fmt::format("{}: {}", run.Where(), why));
  }
}

py::dict Columns(const sim::Run& run, py::handle self) {
  py::dict out;
  out["t_s"] = View(run.t_s, self);
  for (size_t c = 0; c < run.names.size(); ++c) out[py::str(run.names[c])] = View(run.columns[c], self);
  return out;
}

/// pandas, imported on first use: the module imports without it (Debian's python3-pandas).
py::module_ Pandas(const char* what) {
  try {
    return py::module_::import("pandas");
  } catch (py::error_already_set& e) {
    if (!e.matches(PyExc_ImportError)) throw;
    throw py::import_error(fmt::format("{} needs pandas (Debian's python3-pandas, or pip install pandas): {}", what,
                                       std::string(py::str(e.value()))));
  }
}

/// A run as a DataFrame: its columns copied, t_s first, the id in .attrs["run"].
py::object RunFrame(py::handle self) {
  const py::module_ pd = Pandas("Run.to_pandas");
  const sim::Run& run = self.cast<const sim::Run&>();
  py::object frame = pd.attr("DataFrame")(Columns(run, self), py::arg("copy") = true);
  frame.attr("attrs")["run"] = run.id;
  return frame;
}

/// The runs of a tidy DataFrame: one per value of its `run` column (in order of first
/// appearance), else one run named `id` (default the frame's .attrs["run"]). Every other column
/// is a column of the runs, t_s (a column, or the index's name) required; a column whose values
/// are all missing in a run's rows is one that run lacks (a Trace's frame of runs with other
/// columns). Checked as Run() checks its columns.
std::shared_ptr<sim::Trace> TraceFromFrame(const py::object& frame, const std::optional<std::string>& id) {
  const py::module_ pd = Pandas("Trace.from_pandas");
  if (!py::isinstance(frame, pd.attr("DataFrame"))) {
    throw py::type_error(fmt::format("Trace.from_pandas: expected a pandas DataFrame, got {}",
                                     std::string(py::str(py::type::of(frame).attr("__name__")))));
  }
  py::object df = frame;
  const py::list names = df.attr("columns").attr("tolist")();
  if (!names.contains("t_s") && py::str(df.attr("index").attr("name")).equal(py::str("t_s"))) {
    df = df.attr("reset_index")();
  }
  auto trace = std::make_shared<sim::Trace>();
  auto add = [&](const std::string& run_id, const py::object& rows) {
    py::dict columns;
    for (const py::handle name : rows.attr("columns")) {
      if (py::str(name).equal(py::str("run"))) continue;
      const py::object column = rows[name];
      if (column.attr("isna")().attr("all")().cast<bool>() && len(rows) > 0) continue;  // not a column of this run
      columns[py::str(name)] = column.attr("to_numpy")();
    }
    trace->runs.push_back(MakeRun(run_id, columns));
  };
  if (py::list(df.attr("columns").attr("tolist")()).contains("run")) {
    if (id) throw InputError("Trace.from_pandas: the frame has a 'run' column: its values are the run ids (leave run= out)");
    const py::object runs = df["run"];
    for (const py::handle value : pd.attr("unique")(runs)) {
      add(py::str(value), df[runs.attr("__eq__")(value)]);
    }
  } else {
    const py::object attrs = df.attr("attrs");
    if (!id && !attrs.contains("run")) {
      throw InputError("Trace.from_pandas: the frame has no 'run' column and no .attrs['run']: give run='id'");
    }
    add(id ? *id : py::str(attrs["run"]).cast<std::string>(), df);
  }
  return trace;
}

/// A Trace as one tidy DataFrame, as its CSV holds it: a column `run`, then t_s and the runs'
/// columns (missing where a run lacks one).
py::object TraceFrame(py::handle self) {
  const py::module_ pd = Pandas("Trace.to_pandas");
  py::list frames;
  for (const auto& r : self.cast<const sim::Trace&>().runs) {
    py::dict columns;
    columns["run"] = r.id;
    const py::object run = py::cast(&r, py::return_value_policy::reference_internal, self);
    for (const auto& [name, values] : Columns(r, run)) columns[name] = values;
    frames.append(pd.attr("DataFrame")(columns, py::arg("copy") = true));
  }
  if (frames.empty()) return pd.attr("DataFrame")(py::dict(py::arg("run") = py::list(), py::arg("t_s") = py::list()));
  return pd.attr("concat")(frames, py::arg("ignore_index") = true);
}

const sim::Run& RunAt(const sim::Trace& trace, const py::object& key) {
  if (py::isinstance<py::str>(key)) {
    try {
      return trace.FindRun(key.cast<std::string>());
    } catch (const InputError& e) {
      throw py::key_error(e.what());  // the library's text: "no run 'x' in data.csv (runs: ...)"
    }
  }
  if (!PyIndex_Check(key.ptr())) {
    throw py::type_error(fmt::format("run index: expected an int, a run id or a slice, got {}",
                                     std::string(py::str(py::type::of(key).attr("__name__")))));
  }
  py::ssize_t i = key.cast<py::ssize_t>();
  const auto n = static_cast<py::ssize_t>(trace.runs.size());
  if (i < 0) i += n;
  if (i < 0 || i >= n) throw py::index_error(fmt::format("run index {} out of range ({} runs)", key.cast<py::ssize_t>(), n));
  return trace.runs[static_cast<size_t>(i)];
}

/// The Run class: one run's columns as read-only numpy views.
void BindRun(py::module_& m) {
  py::class_<sim::Run>(m, "Run", R"(One run: time-stamped columns from power-on (docs/data-format.md).

Units are in the column names: t_s in s, T_amb and T* in °C, bias_dph in °/h,
P_<source>_W in W. Columns are read-only numpy views of the run's own storage (no copy):
``run["T1"]``, ``run.t_s``, ``run.columns`` (dict name -> array, t_s first, in file order).
Take ``.copy()`` to modify one.

Run(id, columns) makes a run from a mapping name -> 1-D array that must hold "t_s"; the
arrays are copied and checked as the CSV reader checks a file (ValueError otherwise).)")
      .def(py::init(&MakeRun), py::arg("id"), py::arg("columns"))
      .def_property_readonly("id", [](const sim::Run& r) { return r.id; }, "run id (text)")
      .def_property_readonly("source", [](const sim::Run& r) { return r.source; },
                             "file the run was read or simulated from; empty if made in Python")
      .def_property_readonly("first_line", [](const sim::Run& r) { return r.first_line; },
                             "line of its first row in `source`; 0 when not from a data file")
      .def_property_readonly("names", [](const sim::Run& r) { return r.names; }, "data column names after t_s")
      .def_property_readonly("t_s", [](py::object self) { return View(self.cast<const sim::Run&>().t_s, self); },
                             "time since power-on (s), a read-only view")
      .def_property_readonly("columns", [](py::object self) { return Columns(self.cast<const sim::Run&>(), self); },
                             "dict column name -> read-only view, t_s first")
      .def("__getitem__",
           [](py::object self, const std::string& name) {
             const sim::Run& r = self.cast<const sim::Run&>();
             if (name == "t_s") return View(r.t_s, self);
             const int i = r.Find(name);
             if (i < 0) throw py::key_error(fmt::format("{} has no column '{}'", r.Where(), name));
             return View(r.columns[static_cast<size_t>(i)], self);
           },
           py::arg("name"), "column `name` (or t_s) as a read-only view")
      .def("__contains__", [](const sim::Run& r, const std::string& name) { return name == "t_s" || r.Has(name); },
           py::arg("name"))
      .def("__len__", &sim::Run::size, "number of samples")
      .def("to_pandas", &RunFrame,
           "The run as a pandas DataFrame (pandas is imported on first use): a column per column, t_s "
           "first, copied; the id in .attrs['run']. Trace.from_pandas(frame) makes it a run again.")
      .def("add_column", &AddColumn, py::arg("name"), py::arg("values"),
           "Appends a column (copied; e.g. your own compensated bias in °/h, so that write_csv "
           "writes it); checked as Run() checks columns. Views already taken stay valid.")
      .def("__repr__", [](const sim::Run& r) {
        return fmt::format("<rlgtherm.Run '{}': {} samples, columns t_s,{}>", r.id, r.size(), fmt::join(r.names, ","));
      });
}

/// The Trace class: the runs of one data set.
void BindTraceClass(py::module_& m) {
  py::class_<sim::Trace, std::shared_ptr<sim::Trace>>(m, "Trace", R"(Runs of one data set, as one tidy CSV file holds them.

Index by position or run id (``trace["fixed+0"]``), iterate, ``len()``; the runs are views
into the trace (no copy). A slice (``trace[1:3]``) is a new Trace of copies of its runs.
Trace(runs, comments=[]) copies the given Runs into a new trace.)")
      .def(py::init([](const std::vector<const sim::Run*>& runs, std::vector<std::string> comments) {
             auto t = std::make_shared<sim::Trace>();
             for (const sim::Run* r : runs) t->runs.push_back(*r);
             t->comments = std::move(comments);
             return t;
           }),
           py::arg("runs"), py::arg("comments") = std::vector<std::string>{})
      .def_property_readonly("source", [](const sim::Trace& t) { return t.source; },
                             "file the trace was read from; empty if simulated or made in Python")
      .def_readwrite("comments", &sim::Trace::comments, "header comment lines, without the leading '#'")
      .def_property_readonly("runs",
                             [](py::object self) {
                               py::list out;
                               for (auto& r : self.cast<sim::Trace&>().runs)
                                 out.append(py::cast(&r, py::return_value_policy::reference_internal, self));
                               return out;
                             },
                             "list of Run (views into this trace)")
      .def_property_readonly("ids",
                             [](const sim::Trace& t) {
                               std::vector<std::string> ids;
                               for (const auto& r : t.runs) ids.push_back(r.id);
                               return ids;
                             },
                             "run ids in file order")
      .def("__len__", [](const sim::Trace& t) { return t.runs.size(); })
      .def("__getitem__",
           [](const sim::Trace& t, const py::slice& slice) {
             size_t start = 0, stop = 0, step = 0, length = 0;
             if (!slice.compute(t.runs.size(), &start, &stop, &step, &length)) throw py::error_already_set();
             auto out = std::make_shared<sim::Trace>();
             out->source = t.source;
             out->comments = t.comments;
             for (size_t k = 0; k < length; ++k) out->runs.push_back(t.runs[start + k * step]);
             return out;
           },
           py::arg("key"), "a new Trace of the runs of a slice, copied (as Trace(runs) copies them)")
      .def("__getitem__", &RunAt, py::return_value_policy::reference_internal, py::arg("key"),
           "run by position or by id (KeyError listing the ids for an unknown one)")
      .def("__iter__", [](py::object self) { return py::iter(self.attr("runs")); })
      .def("to_pandas", &TraceFrame,
           "The runs as one tidy pandas DataFrame, as the CSV holds them: a column 'run' (the id), then "
           "t_s and the runs' columns, copied (missing where a run lacks a column). pandas is imported on "
           "first use.")
      .def_static("from_pandas", &TraceFromFrame, py::arg("frame"), py::arg("run") = py::none(),
                  R"(A Trace from a pandas DataFrame, checked as Run() checks columns. With a column 'run': a run
per id, in order of first appearance, each of the columns its rows have values in (a tidy frame,
as Trace.to_pandas gives). Without: one run named `run` (default the frame's .attrs['run'], which
Run.to_pandas sets). t_s (s) is a column, or the index when it is named t_s; the other columns
are the run's (°C, °/h, W by their names). The values are copied.)")
      .def("__repr__", [](const sim::Trace& t) {
        std::vector<std::string> ids;
        for (const auto& r : t.runs) ids.push_back(r.id);
        return fmt::format("<rlgtherm.Trace: {} runs ({})>", t.runs.size(), fmt::join(ids, ", "));
      });
}

/// read_csv and import_columns: a Trace from a tidy CSV or a measured log.
void BindReaders(py::module_& m) {
  m.def(
      "read_csv",
      [](const py::object& path, bool require_bias, const std::vector<std::string>& keep_columns) {
        io::CsvReadOptions o;
        o.require_bias = require_bias;
        o.keep_columns = keep_columns;
        const std::string p = PathOf(path);
        io::CsvReadResult r;
        {
          py::gil_scoped_release release;
          r = io::ReadTraceCsv(p, o);
        }
        Warn(r.warnings);
        return std::make_shared<sim::Trace>(std::move(r.trace));
      },
      py::arg("path"), py::arg("require_bias") = true, py::arg("keep_columns") = std::vector<std::string>{},
      R"(Reads a tidy CSV (docs/data-format.md) into a Trace, with the CLI's checks and messages.

require_bias: False for thermal-only data (no bias_dph column).
keep_columns: extra columns to keep (e.g. your own compensated bias, °/h); each must exist.
The "ignored extra columns" note becomes a UserWarning. Bad input: ValueError naming the
file, line and column.)");

  m.def(
      "import_columns",
      [](const py::object& path, const std::string& time, const py::object& temp, const std::string& rate,
         const std::optional<std::string>& run, const std::vector<double>& split_at) {
        // temp: a list of column names, or one string of them joined by commas as --temp takes it.
        std::vector<std::string> temps;
        if (py::isinstance<py::str>(temp)) {
          std::stringstream in(temp.cast<std::string>());
          for (std::string name; std::getline(in, name, ',');) temps.push_back(name);
        } else {
          temps = temp.cast<std::vector<std::string>>();
        }
        const std::string p = PathOf(path);
        std::shared_ptr<sim::Trace> trace;
        {
          py::gil_scoped_release release;
          trace = std::make_shared<sim::Trace>(io::ImportColumnsAsWritten(p, time, temps, rate, run.value_or(""), split_at));
        }
        // The command's warnings on stderr (a temperature that looks like °F) as UserWarnings.
        std::vector<std::string> warnings;
        for (const auto& w : io::FahrenheitWarnings(*trace)) warnings.push_back(fmt::format("{}: {}", p, w));
        Warn(warnings);
        return trace;
      },
      py::arg("path"), py::kw_only(), py::arg("time"), py::arg("temp"), py::arg("rate"), py::arg("run") = py::none(),
      py::arg("split_at") = std::vector<double>{},
      R"(Reads a measured log as `rlgtherm import columns` does, with its checks and messages: any
delimited log with one header row (comma, tab or semicolon; with tab or semicolon a decimal
comma reads as a point). write_csv of the Trace is the command's output byte for byte.

time: "COL:UNIT", the time column and its unit (s, ms, us, ns; no default), counted from the
first row. temp: the temperature columns in °C, a list or "A,B" as --temp takes them, written
as T1, T2, ... rate: "COL:UNIT", the rate column (dph, dps, radps; no default), written as
bias_dph in °/h. run: the run id (default: the file name without extension). split_at: times
(s from the first row) at which the log is cut into runs ID-1, ID-2, ... ValueError naming the
log, line and column for what the command refuses.)");
}

/// write_csv: a Trace as the CLI writes it.
void BindWriter(py::module_& m) {
  m.def(
      "write_csv",
      [](const py::object& data, const py::object& path) {
        const auto trace = TraceOf(data);
        const std::string p = PathOf(path);
        // The runs are in memory: the message names the file being written and the runs, not the
        // file they were read or simulated from (their values are what write_csv was given).
        for (const auto& r : trace->runs) {
          const sim::Run& first = trace->runs.front();
          if (r.names != first.names) {
            throw InputError(fmt::format("write_csv {}: run '{}' has columns {} but the first run, '{}', has {}; one CSV "
                                         "holds runs with the same columns (add the column to every run)",
                                         p, r.id, fmt::join(r.names, ","), first.id, fmt::join(first.names, ",")));
          }
        }
        py::gil_scoped_release release;
        io::WriteFileAtomically(p, [&](std::ostream& out) { io::WriteTraceCsv(*trace, out); });
      },
      py::arg("data"), py::arg("path"),
      R"(Writes data (a Trace, used in place; a Run or a list of Runs, copied into one) as tidy CSV
with the writer the CLI uses: the same bytes as `rlgtherm simulate -o` for the same trace
(temperatures 4 decimals, bias 6), whole or not at all. ValueError when runs differ in their
columns (one CSV has one header).)");
}

/// simulate: a scenario file into a Trace.
void BindSimulate(py::module_& m) {
  m.def(
      "simulate",
      [](const py::object& scenario_path, const py::object& seed_arg, const py::object& gyro_arg) {
        const std::string path = PathOf(scenario_path);
        const std::optional<uint64_t> seed = SeedOf(seed_arg);
        // gyro: an int is a gyro of the scenario's [population], as `simulate --gyro I`.
        if (py::isinstance<py::bool_>(gyro_arg)) {
          throw py::type_error("gyro: expected a Gyro, a gyro file's path or the index of a gyro of the scenario's "
                               "[population], got bool");
        }
        const bool index = PyIndex_Check(gyro_arg.ptr());
        if (index && (gyro_arg.cast<py::int_>() < py::int_(0) ||
                      gyro_arg.cast<py::int_>() > py::int_(std::numeric_limits<uint64_t>::max()))) {
          throw InputError(fmt::format("gyro {}: expected the index of a gyro of the scenario's [population], 0 or more",
                                       py::repr(gyro_arg).cast<std::string>()));
        }
        sim::GyroConfig loaded;
        const sim::GyroConfig* gyro = gyro_arg.is_none() || index ? nullptr : &GyroOf(gyro_arg, loaded);
        const std::optional<uint64_t> member = index ? std::optional(gyro_arg.cast<uint64_t>()) : std::nullopt;
        std::shared_ptr<sim::Trace> trace;
        RunInterruptibly([&](const Interrupt& interrupt) {
          sim::Scenario sc = io::LoadScenario(path);
          uint64_t s = seed.value_or(sc.seed);
          if (gyro) sc.gyro = *gyro;
          if (sc.population && !gyro && !member) {
            throw InputError(fmt::format("{}: the scenario has a [population] of {} gyros: give gyro=I (0 ... {}), or a "
                                         "Gyro for its nominal gyro",
                                         path, sc.population->count, sc.population->count - 1));
          }
          if (member) {
            if (!sc.population) throw InputError(fmt::format("{}: gyro={} needs a [population] in the scenario", path, *member));
            s = sim::UsePopulationGyro(sc, s, *member);
          }
          // Ctrl-C stops between runs.
          const auto between_runs = [&](size_t, size_t) { interrupt.Check(); };
          trace = std::make_shared<sim::Trace>(sim::SimulateScenario(sc, s, between_runs));
          sim::CheckReadable(sc, *trace);
        });
        return trace;
      },
      py::arg("scenario_path"), py::arg("seed") = py::none(), py::arg("gyro") = py::none(),
      R"(Simulates every run of a scenario or suite file (scenarios/README.md) into a Trace.

The columns are those of `rlgtherm simulate` (t_s in s; T_amb, T1.. in °C; bias_dph in °/h;
P_<source>_W in W), at full double precision (the CSV rounds them); write_csv(trace, path)
gives the CLI's file byte for byte for the same seed and scenario path (the path is in a
comment line). seed: default the scenario's `seed`; an int from 0 to 2^64 - 1. gyro: a Gyro
(load_gyro) or a gyro file's path, to use instead of the scenario's; or an int i, gyro i of
the scenario's [population] (drawn from the seed and i, simulated with its own seed), as
`rlgtherm simulate --gyro i`, which a scenario with a [population] needs. Releases the GIL;
Ctrl-C stops it between runs (KeyboardInterrupt).)");
}

}  // namespace

void BindTrace(py::module_& m) {
  BindRun(m);
  BindTraceClass(m);
  BindReaders(m);
  BindWriter(m);
  BindSimulate(m);
}

}  // namespace rlg::python
