#pragma once
// Conversions between the libraries' types and Python objects, shared by the bindings.
// Where data is copied and where it is not (docs/python.md, "Copies"):
//  - C++ columns reach Python as read-only numpy views (View) or as arrays that take over a
//    vector the library returned (Adopt): no copy either way;
//  - Python arrays reach the libraries, which store std::vector<double>, as copies (ToVector).

#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <string>
#include <vector>

#include "model/compensation_model.h"
#include "model/guo2006.h"
#include "sim/gyro.h"
#include "sim/trace.h"

namespace rlg::python {

namespace py = pybind11;

/// A JSON value as Python objects (dict, list, str, int, float, bool, None). A non-finite
/// number becomes None, as nlohmann writes it in the CLI's JSON (e.g. an infinite trend error).
py::object ToPython(const nlohmann::json& j);

/// A read-only 1-D float64 view of `v`; `owner` (the Python object that keeps `v` alive)
/// becomes the array's base.
py::array_t<double> View(const std::vector<double>& v, py::handle owner);

/// A 1-D float64 array that takes over `v` (no copy; the array owns the vector).
py::array_t<double> Adopt(std::vector<double>&& v);

/// A copy of a 1-D array-like of numbers as doubles; ValueError naming `what` unless 1-D.
std::vector<double> ToVector(py::handle values, const std::string& what);

/// Data arguments: a Trace (used in place), a Run or a sequence of Runs (copied into a new
/// Trace), or a path (read as read_csv does, warnings as Python warnings).
std::shared_ptr<const sim::Trace> TraceOf(py::handle data, bool require_bias = true);

/// Coefficients arguments: a dict with the keys of `rlgtherm fit -o` (what fit() returns) or
/// the path of such a file; checked as `compensate --coeffs` checks the file.
model::Guo2006Coefficients CoefficientsOf(py::handle coefficients);

/// The same for any model of the family (model/compensation_model.h): a dict as fit() returns
/// it for any model, or the path of any model's coefficient file.
model::FittedModel ModelOf(py::handle coefficients);

/// A str or os.PathLike as a path string (os.fspath).
std::string PathOf(py::handle path);

/// Gyro arguments: a Gyro (returned as is) or the path of a gyro file (loaded into `loaded`).
const sim::GyroConfig& GyroOf(py::handle gyro, sim::GyroConfig& loaded);

/// Seed arguments: None (nullopt: the file's seed) or an int from 0 to 2^64 - 1, as the CLI's
/// --seed; ValueError for one out of that range, TypeError for anything else.
std::optional<uint64_t> SeedOf(py::handle seed);

/// InputError (ValueError) unless 0 <= threads <= 1024 (0: one per core), the bound of the
/// population and plan functions' `threads`.
void CheckThreads(int threads);

/// What a Compensator may be fed, sample after sample (update, update_many): values a run may
/// hold (sim/trace_limits.h, the CSV reader's limits) and a time later than the previous
/// sample's. One NaN bias in the B0 window would make every later output NaN, a NaN Ti at
/// power-on too, and time going back breaks the window and the rate terms.
class SampleCheck {
 public:
  /// `channels`: the temperature channels the compensator takes, in order.
  explicit SampleCheck(std::vector<std::string> channels) : channels_(std::move(channels)) {}
  /// What is wrong with the sample (t_s, T[0..channels), bias_dph) after those accepted so far;
  /// empty when nothing.
  std::string Problem(double t_s, const double* T, double bias_dph) const;
  void Accept(double t_s) { last_t_s_ = t_s; has_last_ = true; }
  /// A new run: any time may come first.
  void Reset() { has_last_ = false; }

 private:
  std::vector<std::string> channels_;
  double last_t_s_ = 0.0;
  bool has_last_ = false;
};

/// Emits one Python UserWarning per text (the CLI prints them as "rlgtherm: warning: ...").
void Warn(const std::vector<std::string>& warnings);

}  // namespace rlg::python
