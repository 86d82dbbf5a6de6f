// Populations (docs/results.md, Populations): population_count, population_gyros and population_summary over
// validation/population_suite.h. A shard is the dict population_gyros returns: one row per
// gyro, so gyros run anywhere (threads, processes, Dask workers) and population_summary
// reduces the shards, in any order, to the JSON of `rlgtherm validate SUITE --json`.

#include <fmt/format.h>
#include <optional>
#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include "io/process_memory.h"
#include "python/bindings.h"
#include "python/convert.h"
#include "python/interrupt.h"
#include "sim/errors.h"
#include "validation/population_report.h"
#include "validation/population_suite.h"

namespace rlg::python {
namespace {

using validation::GyroOutcome;
using validation::PopulationSuite;

/// The suite file as `validate SUITE [--seed S]` loads it.
validation::SuiteSpec SpecOf(py::handle suite, std::optional<uint64_t> seed) {
  validation::SuiteSpec spec = validation::LoadSuite(PathOf(suite));
  if (seed) spec.seed = *seed;
  return spec;
}

/// compensator=: a callable fit(calibration: Trace) -> (Run -> compensated bias), named by its
/// __name__, or a (name, fit) pair; `name_only` (the summary, which needs the name alone): a
/// name too. None: no compensator of the user's.
struct UserCompensator {
  std::string name;
  py::object fit;  ///< None where only the name was given
};

std::optional<UserCompensator> UserCompensatorOf(const py::object& arg, bool name_only) {
  if (arg.is_none()) return std::nullopt;
  const char* takes = name_only ? "a fit function, a (name, fit) pair or a name" : "a fit function or a (name, fit) pair";
  if (name_only && py::isinstance<py::str>(arg)) return UserCompensator{arg.cast<std::string>(), py::none()};
  if (py::isinstance<py::tuple>(arg)) {
    const auto t = py::reinterpret_borrow<py::tuple>(arg);
    if (t.size() != 2 || !py::isinstance<py::str>(t[0]) || !PyCallable_Check(t[1].ptr())) {
      throw py::type_error(fmt::format("compensator: expected {}; a tuple must be (name: str, fit: callable)", takes));
    }
    return UserCompensator{t[0].cast<std::string>(), t[1]};
  }
  if (!PyCallable_Check(arg.ptr())) {
    throw py::type_error(fmt::format("compensator: expected {}, got {}", takes,
                                     std::string(py::str(py::type::of(arg).attr("__name__")))));
  }
  if (!py::hasattr(arg, "__name__") || !py::isinstance<py::str>(arg.attr("__name__"))) {
    throw InputError("compensator: this callable has no __name__ to name its rows by: give (name, fit)");
  }
  return UserCompensator{arg.attr("__name__").cast<std::string>(), arg};
}

/// A copy of `runs` as a Trace of Python's own: what Python keeps of it outlives the gyro.
std::shared_ptr<sim::Trace> Copied(const std::vector<const sim::Run*>& runs) {
  auto t = std::make_shared<sim::Trace>();
  for (const sim::Run* r : runs) t->runs.push_back(*r);
  return t;
}

/// The user's compensator as the suite's external one: per gyro and fit, fit(calibration) on a
/// copy of the training runs, then its result on a copy of each run to compensate, with the
/// GIL held (the copies are made without it). `interrupt` points at the running call's
/// Interrupt while gyros run: Ctrl-C stops at the next fit or run.
validation::ExternalCompensator External(const UserCompensator& user, const Interrupt* const* interrupt) {
  validation::ExternalCompensator e;
  e.name = user.name;
  if (user.fit.is_none()) return e;
  // Borrowed: the caller's argument holds the callable for the whole call, and no reference
  // count is touched without the GIL when the suite is moved or copied.
  const py::handle fit = user.fit;
  const std::string name = user.name;
  e.compensate = [fit, name, interrupt](uint64_t gyro, const std::vector<const sim::Run*>& training,
                                        const std::vector<const sim::Run*>& runs) {
    auto check = [&] {
      if (*interrupt) (*interrupt)->Check();
    };
    check();
    const std::shared_ptr<sim::Trace> calibration = Copied(training), held = Copied(runs);
    std::vector<std::vector<double>> out;
    py::gil_scoped_acquire gil;
    const py::object held_py = py::cast(held);
    const py::object compensate = fit(py::cast(calibration));
    if (!PyCallable_Check(compensate.ptr())) {
      throw py::type_error(fmt::format("compensator '{}' on gyro {}: fit returned {}, expected a callable that maps a "
                                       "Run to its compensated bias",
                                       name, gyro, std::string(py::str(py::type::of(compensate).attr("__name__")))));
    }
    const py::list held_runs = held_py.attr("runs");  // views into `held`, which they keep alive
    for (size_t k = 0; k < runs.size(); ++k) {
      check();
      const py::object run = held_runs[k];
      out.push_back(ToVector(compensate(run), fmt::format("compensator '{}' on gyro {}, run '{}'", name, gyro,
                                                          runs[k]->id)));
    }
    return out;
  };
  return e;
}

/// The suite ready to run gyros: its constructor runs gyro 0 once (population_suite.h), so
/// without the GIL (an external compensator is laid out, not called, there).
PopulationSuite SuiteOf(py::handle suite, std::optional<uint64_t> seed,
                        std::optional<validation::ExternalCompensator> external = std::nullopt) {
  validation::SuiteSpec spec = SpecOf(suite, seed);
  py::gil_scoped_release release;
  return PopulationSuite(std::move(spec), std::move(external));
}

/// The column names of a shard's matrices, in the suite's order.
struct Layout {
  std::vector<std::string> parameters, metrics, checks;
  explicit Layout(const PopulationSuite& s) : parameters(s.parameters()) {
    for (const auto& m : s.metrics()) metrics.push_back(m.Column());
    for (const auto& c : s.checks()) checks.push_back(c.Label());
  }
};

template <typename T>
py::array_t<T> Matrix(size_t rows, size_t cols) {
  return py::array_t<T>({static_cast<py::ssize_t>(rows), static_cast<py::ssize_t>(cols)});
}

py::dict Gyros(const py::object& suite_path, uint64_t first, std::optional<uint64_t> count, int threads,
               const py::object& seed, const py::object& compensator) {
  CheckThreads(threads);
  const std::optional<UserCompensator> user = UserCompensatorOf(compensator, false);
  const Interrupt* running = nullptr;  // the Interrupt of RunInterruptibly below, for the compensator
  const PopulationSuite suite =
      SuiteOf(suite_path, SeedOf(seed), user ? std::optional(External(*user, &running)) : std::nullopt);
  const uint64_t total = suite.population().count();
  if (first > total) {
    throw InputError(fmt::format("{}: first gyro {} is beyond the population of {}", suite.spec().path, first, total));
  }
  const uint64_t n = count.value_or(total - first);
  if (n > total - first) {  // before the arrays are allocated (RunPopulation checks the same)
    throw InputError(fmt::format("{}: gyros {}..{} are not all in a population of {}", suite.spec().path, first,
                                 first + n - 1, total));
  }
  const Layout layout(suite);
  const size_t np = layout.parameters.size(), nm = layout.metrics.size(), nc = layout.checks.size();
  // Allocated here and filled without the GIL: the arrays are referenced until returned.
  py::array_t<uint64_t> gyro(static_cast<py::ssize_t>(n)), gyro_seed(static_cast<py::ssize_t>(n));
  auto parameters = Matrix<double>(n, np), metrics = Matrix<double>(n, nm);
  auto passed = Matrix<bool>(n, nc);
  auto value = Matrix<double>(n, nc), limit = Matrix<double>(n, nc);
  uint64_t* g = gyro.mutable_data();
  uint64_t* s = gyro_seed.mutable_data();
  double* p = parameters.mutable_data();
  double* m = metrics.mutable_data();
  bool* cp = passed.mutable_data();
  double* cv = value.mutable_data();
  double* cl = limit.mutable_data();
  RunInterruptibly([&](const Interrupt& interrupt) {
    running = &interrupt;
    // RunPopulation checks first and count against the population; rows come in index order.
    // Ctrl-C stops it between gyros (and the user's compensator between runs): the arrays,
    // half filled, are dropped.
    validation::RunPopulation(suite, first, n, threads, [&](const GyroOutcome& o) {
      interrupt.Check();
      const size_t r = o.index - first;
      g[r] = o.index;
      s[r] = o.seed;
      std::copy(o.parameters.begin(), o.parameters.end(), p + r * np);
      std::copy(o.metrics.begin(), o.metrics.end(), m + r * nm);
      std::copy(o.check_passed.begin(), o.check_passed.end(), cp + r * nc);
      std::copy(o.check_value.begin(), o.check_value.end(), cv + r * nc);
      std::copy(o.check_limit.begin(), o.check_limit.end(), cl + r * nc);
    });
  });
  py::dict out;
  out["gyro"] = gyro;
  out["seed"] = gyro_seed;
  out["parameters"] = parameters;
  out["parameter_names"] = layout.parameters;
  out["metrics"] = metrics;
  out["metric_names"] = layout.metrics;
  out["check_passed"] = passed;
  out["check_value"] = value;
  out["check_limit"] = limit;
  out["check_names"] = layout.checks;
  return out;
}

/// One shard's arrays, checked against the suite's layout, with pointers the summary reads
/// without the GIL (the arrays are held here).
struct Shard {
  py::array_t<uint64_t, py::array::c_style | py::array::forcecast> gyro, seed;
  py::array_t<double, py::array::c_style | py::array::forcecast> parameters, metrics, value, limit;
  py::array_t<bool, py::array::c_style | py::array::forcecast> passed;
  size_t rows = 0;
};

Shard ShardOf(const py::handle& shard, size_t k, const PopulationSuite& suite, const Layout& layout) {
  const std::string where = fmt::format("{}: shard {}", suite.spec().path, k);
  if (!py::isinstance<py::dict>(shard)) {
    throw InputError(fmt::format("{}: expected a dict of population_gyros, got {}", where,
                                 std::string(py::str(py::type::of(shard).attr("__name__")))));
  }
  const auto d = py::reinterpret_borrow<py::dict>(shard);
  auto item = [&](const char* key) {
    if (!d.contains(key)) throw InputError(fmt::format("{}: no '{}' (a dict of population_gyros has it)", where, key));
    return d[key];
  };
  auto names = [&](const char* key, const std::vector<std::string>& expected) {
    std::vector<std::string> given;
    try {
      given = py::cast<std::vector<std::string>>(item(key));
    } catch (const py::cast_error&) {
      throw InputError(fmt::format("{}: '{}' is not a list of names", where, key));
    }
    if (given != expected) {
      throw InputError(fmt::format("{}: its {} are not this suite's (a shard of another suite, or of another "
                                   "compensator= than this call's?)",
                                   where, key));
    }
  };
  names("parameter_names", layout.parameters);
  names("metric_names", layout.metrics);
  names("check_names", layout.checks);
  Shard s;
  auto shape_of = [](const py::array& a) {
    return fmt::format("({})", fmt::join(std::vector<py::ssize_t>(a.shape(), a.shape() + a.ndim()), ", "));
  };
  auto array = [&](auto& a, const char* key, std::optional<size_t> cols) {
    a = std::decay_t<decltype(a)>::ensure(item(key));
    if (!a) throw InputError(fmt::format("{}: '{}' is not an array of numbers", where, key));
    const bool ok = cols ? a.ndim() == 2 && static_cast<size_t>(a.shape(0)) == s.rows &&
                               static_cast<size_t>(a.shape(1)) == *cols
                         : a.ndim() == 1 && static_cast<size_t>(a.shape(0)) == s.rows;
    if (!ok) {
      throw InputError(fmt::format("{}: '{}' has shape {}, expected ({}{}): one row per gyro{}", where, key,
                                   shape_of(a), s.rows, cols ? fmt::format(", {}", *cols) : ",",
                                   cols ? ", a column per name" : ""));
    }
  };
  s.gyro = decltype(s.gyro)::ensure(item("gyro"));
  if (!s.gyro || s.gyro.ndim() != 1) throw InputError(fmt::format("{}: 'gyro' is not a 1-D array of gyro indices", where));
  s.rows = static_cast<size_t>(s.gyro.shape(0));
  array(s.seed, "seed", std::nullopt);
  array(s.parameters, "parameters", layout.parameters.size());
  array(s.metrics, "metrics", layout.metrics.size());
  array(s.passed, "check_passed", layout.checks.size());
  array(s.value, "check_value", layout.checks.size());
  array(s.limit, "check_limit", layout.checks.size());
  return s;
}

/// Adds a shard's gyros. A gyro outside the population, or with another seed than this suite
/// gives it, comes from another suite, count or seed: refused rather than summarized.
void AddShard(const Shard& s, const PopulationSuite& suite, const Layout& layout,
              validation::PopulationSummary& summary) {
  const size_t np = layout.parameters.size(), nm = layout.metrics.size(), nc = layout.checks.size();
  for (size_t r = 0; r < s.rows; ++r) {
    GyroOutcome o;
    o.index = s.gyro.data()[r];
    o.seed = s.seed.data()[r];
    if (o.index >= suite.population().count()) {
      throw InputError(fmt::format("{}: gyro {} is not in its population of {}", suite.spec().path, o.index,
                                   suite.population().count()));
    }
    const uint64_t expected = sim::Population::GyroSeed(suite.seed(), o.index);
    if (o.seed != expected) {
      throw InputError(fmt::format("{}: gyro {} has seed {}, but this suite (seed {}) gives it {}: a shard of another "
                                   "suite or seed",
                                   suite.spec().path, o.index, o.seed, suite.seed(), expected));
    }
    const double* p = s.parameters.data() + r * np;
    const double* m = s.metrics.data() + r * nm;
    const bool* cp = s.passed.data() + r * nc;
    o.parameters.assign(p, p + np);
    o.metrics.assign(m, m + nm);
    o.check_passed.assign(cp, cp + nc);
    o.check_value.assign(s.value.data() + r * nc, s.value.data() + (r + 1) * nc);
    o.check_limit.assign(s.limit.data() + r * nc, s.limit.data() + (r + 1) * nc);
    summary.Add(o);
  }
}

py::object Summary(const py::object& suite_path, const py::object& shards, const py::object& seed,
                   const py::object& compensator) {
  const std::optional<UserCompensator> user = UserCompensatorOf(compensator, true);
  // The layout needs the compensator's name alone: it is never called here.
  const PopulationSuite suite = SuiteOf(suite_path, SeedOf(seed),
                                        user ? std::optional(validation::ExternalCompensator{user->name, {}}) : std::nullopt);
  const Layout layout(suite);
  std::vector<Shard> parts;
  if (py::isinstance<py::dict>(shards)) {  // one shard given alone
    parts.push_back(ShardOf(shards, 0, suite, layout));
  } else {
    for (const auto& shard : shards) parts.push_back(ShardOf(shard, parts.size(), suite, layout));
  }
  nlohmann::json j;
  {
    py::gil_scoped_release release;  // the shards' arrays are held by `parts`
    validation::PopulationSummary summary(suite);
    for (const auto& s : parts) AddShard(s, suite, layout, summary);
    j = validation::PopulationJson(suite, summary);
  }
  return ToPython(j);
}

}  // namespace

void BindPopulation(py::module_& m) {
  m.def("keep_freed_memory", &io::KeepFreedMemory,
        R"(Makes this process keep freed memory for reuse instead of handing it back to the system
(glibc's mmap and trim thresholds raised to 512 MiB and 1 GiB; nothing elsewhere). A process that
runs many gyros should call it once: each gyro's runs, fits and evaluations allocate afresh, and
page-faulting them back in takes a gyro of scenarios/paper-population.toml from 13 to 36 CPU-ms
(docs/python.md, "Measured plan").
The CLI does it at start; a library must not change its host's allocator unasked, so the module
leaves it to you. rlgtherm_dask's shards call it on the workers.)");
  m.def(
      "population_count",
      [](const py::object& suite) {
        const validation::SuiteSpec spec = SpecOf(suite, std::nullopt);
        if (!spec.population) {
          throw InputError(fmt::format("{}: not a population suite: it has no [population] table", spec.path));
        }
        return spec.population->count;
      },
      py::arg("suite"),
      R"(The number of gyros of a population suite (its [population] count), read from the suite
file alone (nothing is simulated). ValueError for a suite without [population].)");

  m.def("population_gyros", &Gyros, py::arg("suite"), py::arg("first") = 0, py::arg("count") = py::none(),
        py::arg("threads") = 0, py::kw_only(), py::arg("seed") = py::none(), py::arg("compensator") = py::none(),
        R"(Runs gyros first .. first + count - 1 of a population suite, as `rlgtherm validate SUITE`
does (each gyro drawn, simulated, fitted on its own calibration runs, compensated and checked),
and returns them as a shard: a dict of numpy arrays, one row per gyro in index order:

  gyro (uint64), seed (uint64)         the gyro's index and its seed (SplitMix64 of suite seed, i)
  parameters (n x p float64)           its drawn parameters, columns parameter_names
  metrics (n x m float64)              its Table 2 metrics (°/h), columns metric_names: the
                                       per-gyro CSV's names (`validate --gyros`), e.g.
                                       "fixed+60.abs_bias_after_dph"
  check_passed (n x c bool)            its checks, columns check_names ("bias after fixed+60")
  check_value, check_limit (n x c)     what each check measured and its limit; NaN where the
                                       check has no number (best pair)

count None: to the end of the population. threads: gyros in parallel (0: one per core); the
arrays do not depend on it. seed: the suite seed, as `validate --seed`.

compensator: your own compensator, calibrated per gyro as the suite's fits are: a function
fit(calibration: Trace) that returns a callable mapping a Run to its compensated bias (°/h, a
1-D array, one value per sample). For each [[fits]] entry, fit gets a Trace of the gyro's
training runs (the fit's `runs`), and its callable each run the fit compensates. Its rows join
the suite's under its name (fit.__name__, or give (name, fit)): metric_names
"<run>.<name>.<metric>", check_names "<check> <run> [<name>]", evaluated and checked as the
fitted model's. It is called with the GIL held, from the threads running gyros (their C++ runs
without it); the runs it gets are its own copies.

The GIL is released while gyros run; Ctrl-C stops them between gyros (KeyboardInterrupt), and
the compensator between runs. Building the suite runs gyro 0 once (to fix the layout; not the
compensator), so a call costs one gyro more than it returns. population_summary(suite, shards)
reduces shards to the summary.)");

  m.def("population_summary", &Summary, py::arg("suite"), py::arg("shards"), py::kw_only(),
        py::arg("seed") = py::none(), py::arg("compensator") = py::none(),
        R"(The summary of a population suite from shards of population_gyros (a list of their dicts, in
any order, or one dict): exactly the dict of `rlgtherm validate SUITE --json` on those gyros,
{"population": {"suite", "gyro", "gyros", "seed", "parameters", "metrics", "checks"},
"passed"}: each metric's median, p95 and worst with its gyro, each check's failing gyros
against max_failing_fraction. The shards may hold any subset of the population ("gyros" says
how many were summarized); the same gyros give the same dict however they were split.
ValueError for a shard of another layout, count or seed, a gyro given twice, arrays of the
wrong shape, or no gyro at all. seed: as in population_gyros. compensator: as given to
population_gyros (or its name alone): its rows are summarized and checked with the suite's.)");
}

}  // namespace rlg::python
