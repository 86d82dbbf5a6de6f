#include "python/convert.h"

#include <cmath>
#include <limits>
#include <fmt/format.h>
#include <pybind11/stl.h>

#include "io/csv.h"
#include "io/gyro_file.h"
#include "model/coefficients_json.h"
#include "sim/errors.h"
#include "sim/trace_limits.h"

namespace rlg::python {

py::object ToPython(const nlohmann::json& j) {
  using T = nlohmann::json::value_t;
  switch (j.type()) {
    case T::null:
    case T::discarded:
      return py::none();
    case T::boolean:
      return py::bool_(j.get<bool>());
    case T::number_integer:
      return py::int_(j.get<int64_t>());
    case T::number_unsigned:
      return py::int_(j.get<uint64_t>());
    case T::number_float: {
      const double v = j.get<double>();
      return std::isfinite(v) ? py::object(py::float_(v)) : py::object(py::none());
    }
    case T::string:
      return py::str(j.get_ref<const std::string&>());
    case T::array: {
      py::list out;
      for (const auto& e : j) out.append(ToPython(e));
      return out;
    }
    case T::object: {
      py::dict out;
      for (const auto& [key, value] : j.items()) out[py::str(key)] = ToPython(value);
      return out;
    }
    case T::binary:
      break;
  }
  throw std::logic_error("ToPython: a JSON binary value");
}

py::array_t<double> View(const std::vector<double>& v, py::handle owner) {
  py::array_t<double> a({static_cast<py::ssize_t>(v.size())}, {static_cast<py::ssize_t>(sizeof(double))}, v.data(), owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

py::array_t<double> Adopt(std::vector<double>&& v) {
  auto* owned = new std::vector<double>(std::move(v));
  py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<double>*>(p); });
  return py::array_t<double>({static_cast<py::ssize_t>(owned->size())}, {static_cast<py::ssize_t>(sizeof(double))},
                             owned->data(), free_when_done);
}

std::vector<double> ToVector(py::handle values, const std::string& what) {
  const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
  if (!a) throw py::type_error(fmt::format("{}: expected an array of numbers", what));
  if (a.ndim() != 1) throw py::value_error(fmt::format("{}: expected a 1-D array, got {} dimensions", what, a.ndim()));
  return std::vector<double>(a.data(), a.data() + a.size());
}

std::string PathOf(py::handle path) { return py::str(py::module_::import("os").attr("fspath")(path)); }

const sim::GyroConfig& GyroOf(py::handle gyro, sim::GyroConfig& loaded) {
  if (py::isinstance<sim::GyroConfig>(gyro)) return gyro.cast<const sim::GyroConfig&>();
  loaded = io::LoadGyro(PathOf(gyro));
  return loaded;
}

std::optional<uint64_t> SeedOf(py::handle seed) {
  if (seed.is_none()) return std::nullopt;
  if (py::isinstance<py::bool_>(seed) || !PyIndex_Check(seed.ptr())) {
    throw py::type_error(fmt::format("seed: expected an int or None, got {}",
                                     std::string(py::str(py::type::of(seed).attr("__name__")))));
  }
  const py::int_ value = py::reinterpret_steal<py::int_>(PyNumber_Index(seed.ptr()));
  if (!value) throw py::error_already_set();
  if (value < py::int_(0) || value > py::int_(std::numeric_limits<uint64_t>::max())) {
    throw InputError(fmt::format("seed {}: expected an integer from 0 to {}", py::repr(value).cast<std::string>(),
                                 std::numeric_limits<uint64_t>::max()));
  }
  return value.cast<uint64_t>();
}

void CheckThreads(int threads) {
  if (threads < 0 || threads > 1024) {
    throw InputError(fmt::format("threads {}: expected 0 (one per core) to 1024", threads));
  }
}

std::string SampleCheck::Problem(double t_s, const double* T, double bias_dph) const {
  const sim::TraceLimits limits;
  if (!std::isfinite(t_s)) return fmt::format("t_s = {}: not a finite number", t_s);
  if (const std::string why = sim::TimeProblem(t_s, limits); !why.empty()) return fmt::format("t_s = {} s: {}", t_s, why);
  if (has_last_ && !(t_s > last_t_s_)) {
    return fmt::format("t_s = {} s: time does not increase (the sample before was at {} s)", t_s, last_t_s_);
  }
  auto value = [&](const std::string& name, double v) -> std::string {
    const std::string why = std::isfinite(v) ? sim::RangeProblem(sim::RangeOf(name, limits), v) : "not a finite number";
    return why.empty() ? "" : fmt::format("{} = {} at t_s = {} s: {}", name, v, t_s, why);
  };
  for (size_t c = 0; c < channels_.size(); ++c) {
    if (std::string why = value(channels_[c], T[c]); !why.empty()) return why;
  }
  return value("bias_dph", bias_dph);
}

void Warn(const std::vector<std::string>& warnings) {
  if (warnings.empty()) return;
  const py::object warn = py::module_::import("warnings").attr("warn");
  // stacklevel 1: called from C++, the innermost Python frame is the caller's line (2 named its
  // caller, "sys:1" at the top level of a script).
  for (const auto& w : warnings) warn(w, py::handle(PyExc_UserWarning), 1);
}

std::shared_ptr<const sim::Trace> TraceOf(py::handle data, bool require_bias) {
  if (py::isinstance<sim::Trace>(data)) return data.cast<std::shared_ptr<sim::Trace>>();
  if (py::isinstance<py::str>(data) || py::hasattr(data, "__fspath__")) {
    const std::string path = PathOf(data);
    io::CsvReadOptions o;
    o.require_bias = require_bias;
    io::CsvReadResult r;
    {
      py::gil_scoped_release release;
      r = io::ReadTraceCsv(path, o);
    }
    Warn(r.warnings);
    return std::make_shared<const sim::Trace>(std::move(r.trace));
  }
  auto trace = std::make_shared<sim::Trace>();
  if (py::isinstance<sim::Run>(data)) {
    trace->runs.push_back(data.cast<const sim::Run&>());
    return trace;
  }
  if (py::isinstance<py::sequence>(data)) {
    for (const py::handle r : data.cast<py::sequence>()) {
      if (!py::isinstance<sim::Run>(r)) throw py::type_error("data: expected a Trace, a Run, a list of Runs or a CSV path");
      trace->runs.push_back(r.cast<const sim::Run&>());
    }
    return trace;
  }
  throw py::type_error("data: expected a Trace, a Run, a list of Runs or a CSV path");
}

model::Guo2006Coefficients CoefficientsOf(py::handle coefficients) {
  if (py::isinstance<py::dict>(coefficients)) {
    // Through the file format's own reader, so a dict is checked as a file is; indented so that
    // a message's line number points at the key.
    const std::string text = py::str(py::module_::import("json").attr("dumps")(coefficients, py::arg("indent") = 2));
    return model::ParseCoefficients(text, "coefficients");
  }
  if (py::isinstance<py::str>(coefficients) || py::hasattr(coefficients, "__fspath__")) {
    return model::ReadCoefficientsFile(PathOf(coefficients));
  }
  throw py::type_error("coefficients: expected a dict as fit() returns it or the path of a coefficients JSON file");
}

model::FittedModel ModelOf(py::handle coefficients) {
  if (py::isinstance<py::dict>(coefficients)) {
    const std::string text = py::str(py::module_::import("json").attr("dumps")(coefficients, py::arg("indent") = 2));
    return model::ParseModel(text, "coefficients");
  }
  if (py::isinstance<py::str>(coefficients) || py::hasattr(coefficients, "__fspath__")) {
    return model::ReadModelFile(PathOf(coefficients));
  }
  throw py::type_error("coefficients: expected a dict as fit() returns it or the path of a coefficients JSON file");
}

}  // namespace rlg::python
