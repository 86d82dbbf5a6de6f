#include "io/scenario_file.h"

#include <cmath>
#include <filesystem>
#include <fmt/format.h>
#include <set>
#include <toml++/toml.h>

#include "io/csv.h"
#include "io/gyro_file.h"
#include "io/input_file.h"
#include "io/toml_reader.h"
#include "sim/errors.h"
#include "sim/limits.h"

namespace rlg::io {

using sim::Correlation;
using sim::IntegratorOptions;
using sim::Population;
using sim::PopulationSpec;
using sim::Profile;
using sim::RunIdProblem;
using sim::RunSpec;
using sim::Scenario;
using sim::Spread;
using sim::ThermalMethod;
using sim::ThermalNetwork;
namespace limits = sim::limits;

namespace {

// A profile's values stay within what the tidy CSV holds (sim/limits.h): an ambient within
// the temperature range, a power within the power limit; its times within the time limit.
std::pair<double, double> ValueLimits(const std::string& unit) {
  if (unit == "C") return {limits::kMinTemperature_C, limits::kMaxTemperature_C};
  return {-limits::kMaxAbsPower_W, limits::kMaxAbsPower_W};
}

void CheckPoints(const TomlReader& t, const std::string& key, const std::vector<std::pair<double, double>>& points,
                 const std::string& unit) {
  const auto [lo, hi] = ValueLimits(unit);
  for (size_t i = 0; i < points.size(); ++i) {
    const auto [time, value] = points[i];
    if (!(std::abs(time) <= limits::kMaxAbsTime_s)) {
      t.Fail(key, fmt::format("entry {}: time {:g} s is beyond ±{:g} s", i + 1, time, limits::kMaxAbsTime_s));
    }
    if (!(value >= lo && value <= hi)) {
      t.Fail(key, fmt::format("entry {}: value {:g} {} is outside {:g}...{:g} {}", i + 1, value, unit, lo, hi, unit));
    }
  }
}

// A population is simulated one gyro at a time, so its size only bounds the run time; 1e9
// gyros keep the index and the CSV's id column well inside what any consumer reads exactly.
constexpr int64_t kMaxCount = 1'000'000'000;
// A relative sigma of 1 already puts a normal draw below zero one time in six: wider is a
// distribution that is not a part-to-part spread.
constexpr double kMaxRelativeSigma = 1.0;

}  // namespace

PopulationSpec ReadPopulation(const TomlReader& table) {
  PopulationSpec p;
  p.file = table.file();
  const int64_t count = table.Integer("count", 0);
  if (count < 1 || count > kMaxCount) table.Fail("count", fmt::format("expected a gyro count in 1...{}", kMaxCount));
  p.count = static_cast<uint64_t>(count);
  for (const auto& t : table.ArrayOfTables("spread")) {
    Spread s;
    s.line = t.line();
    s.parameter = t.String("parameter");
    const std::string kind = t.String("distribution");
    if (kind == "normal") {
      s.kind = Spread::Kind::kNormal;
      if (t.Has("sigma") == t.Has("relative_sigma")) {
        t.FailHere("a normal spread takes one of sigma (in the parameter's unit) or relative_sigma");
      }
      if (t.Has("sigma")) s.sigma = t.Positive("sigma", true);
      if (t.Has("relative_sigma")) s.relative_sigma = t.InRange("relative_sigma", 0.0, kMaxRelativeSigma);
    } else if (kind == "lognormal") {
      s.kind = Spread::Kind::kLogNormal;
      s.relative_sigma = t.InRange("relative_sigma", 0.0, kMaxRelativeSigma);
    } else if (kind == "uniform") {
      s.kind = Spread::Kind::kUniform;
      const auto r = t.Numbers("range");
      if (r.size() != 2 || !(r[0] <= r[1])) t.Fail("range", "expected [lo, hi] with lo <= hi, offsets from the nominal");
      s.lo = r[0];
      s.hi = r[1];
    } else {
      t.Fail("distribution", "expected \"normal\", \"lognormal\" or \"uniform\"");
    }
    t.Finish();
    p.spreads.push_back(std::move(s));
  }
  for (const auto& t : table.ArrayOfTables("correlation")) {
    Correlation c;
    c.line = t.line();
    const auto names = t.Strings("parameters");
    if (names.size() != 2 || names[0] == names[1]) t.Fail("parameters", "expected two different parameter names");
    c.a = names[0];
    c.b = names[1];
    c.coefficient = t.InRange("coefficient", -0.999, 0.999);  // |rho| = 1 is one parameter, not two
    t.Finish();
    p.correlations.push_back(std::move(c));
  }
  table.Finish();
  return p;
}

Profile ReadProfile(const TomlReader& t, const std::string& u, double duration_s) {
  const std::string kind = t.String("profile");
  const auto [lo, hi] = ValueLimits(u);
  const double max_t = limits::kMaxAbsTime_s;
  try {
    Profile p = Profile::Constant(0.0);
    if (kind == "constant") {
      p = Profile::Constant(t.InRange("value_" + u, lo, hi));
    } else if (kind == "ramp") {
      const double start_s = t.InRange("start_s", -max_t, max_t, 0.0);
      // A ramp that starts after the run ends is a constant that was meant to be a ramp.
      if (start_s >= duration_s) {
        t.Fail("start_s", fmt::format("the ramp starts at {:g} s, at or after the run's end ({:g} s, duration_s): the run "
                                      "would hold start_{} throughout; expected a start within the run",
                                      start_s, duration_s, u));
      }
      p = Profile::Ramp(t.InRange("start_" + u, lo, hi), t.Number("rate_" + u + "_per_min") / 60.0, start_s,
                        t.InRange("end_" + u, lo, hi));
    } else if (kind == "table") {
      const auto points = t.Pairs("points");
      CheckPoints(t, "points", points, u);
      p = Profile::Table(points);
    } else if (kind == "steps") {
      const double initial = t.InRange("initial_" + u, lo, hi);
      const auto steps = t.Pairs("steps");
      CheckPoints(t, "steps", steps, u);
      p = Profile::Steps(initial, steps);
    } else if (kind == "sine") {
      const double mean = t.InRange("mean_" + u, lo, hi);
      const double amplitude = t.Number("amplitude_" + u);
      if (!(mean - std::abs(amplitude) >= lo && mean + std::abs(amplitude) <= hi)) {
        t.Fail("amplitude_" + u, fmt::format("mean ± amplitude must stay within {:g}...{:g} {}", lo, hi, u));
      }
      // A period from the shortest sample period to the time limit; a phase within one turn.
      p = Profile::Sine(mean, amplitude, t.InRange("period_s", limits::kMinSamplePeriod_s, max_t),
                        t.InRange("phase_deg", -360.0, 360.0, 0.0) * M_PI / 180.0);
    } else {
      t.Fail("profile", fmt::format("unknown profile '{}'; expected constant, ramp, table, steps or sine", kind));
    }
    t.Finish();
    return p;
  } catch (const std::invalid_argument& e) {
    t.FailHere(e.what());
  }
}

namespace {

/// The scenario's [solver] table: the thermal network's integration method and CVODE's
/// tolerances (sim/solver_options.h).
sim::SolverOptions ReadSolver(const TomlReader& solver) {
  sim::SolverOptions s;
  const std::string method = solver.String("method", "auto");
  if (method == "auto") {
    s.method = ThermalMethod::kAuto;
  } else if (method == "cvode") {
    s.method = ThermalMethod::kCvode;
  } else if (method == "exact") {
    s.method = ThermalMethod::kExactLinear;
  } else {
    solver.Fail("method", "expected \"auto\", \"cvode\" or \"exact\"");
  }
  IntegratorOptions& cv = s.cvode;
  cv.rtol = solver.Number("rtol", cv.rtol);
  cv.atol = solver.Number("atol_C", cv.atol);
  cv.max_steps = solver.Integer("max_steps", cv.max_steps);
  cv.max_step_s = solver.Number("max_step_s", cv.max_step_s);
  std::string why;
  if (!cv.IsValid(&why)) solver.FailHere(why);
  solver.Finish();
  return s;
}

}  // namespace

Scenario LoadScenario(const std::string& path) {
  if (!IsRegularFile(path)) {
    throw InputError(fmt::format("{}: scenario file not found (expected a TOML scenario, see scenarios/README.md)", path));
  }
  const auto doc = ParseTomlFile(path);
  const TomlReader root(*doc, path, "scenario");
  if (root.Has("scenarios") && !root.Has("gyro")) {
    // "Suite" names both a validate suite and a scenario's runs: say which file this is.
    const auto listed = root.Strings("scenarios");
    throw InputError(fmt::format("{}: this is a validate suite (it lists scenarios = [...]), not a scenario: run "
                                 "`rlgtherm validate {}`; simulate reads a scenario file (gyro = ..., [[runs]]){}",
                                 path, path,
                                 listed.empty() ? std::string()
                                                : fmt::format(", such as the suite's first, {}", listed.front())));
  }
  Scenario sc;
  sc.path = path;
  const std::string gyro_rel = root.String("gyro");
  const std::filesystem::path gyro_path = std::filesystem::path(path).parent_path() / gyro_rel;
  // A gyro file that cannot be read is named with the scenario's line that names it.
  if (!IsRegularFile(gyro_path)) {
    root.Fail("gyro", fmt::format("{}: gyro file not found (expected a TOML gyro file, relative to the scenario file)",
                                  gyro_path.lexically_normal().string()));
  }
  sc.gyro = LoadGyro(gyro_path.lexically_normal().string());
  ReadAndApplyEffects(root, sc.gyro);
  try {
    ThermalNetwork check(sc.gyro.network);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: with its effects: {}", path, e.what()));
  }
  const int64_t seed = root.Integer("seed", 1);
  if (seed < 0) root.Fail("seed", "expected a non-negative integer");
  sc.seed = static_cast<uint64_t>(seed);

  if (const auto solver = root.OptionalTable("solver")) sc.solver = ReadSolver(*solver);
  // Run length and sample period: within the time limit, no faster than the shortest period a
  // gyro's thermal data has, and few enough samples to hold in memory (sim/limits.h).
  auto duration = [](const TomlReader& t, double fallback) {
    t.Positive("duration_s", fallback);
    return t.InRange("duration_s", 0.0, limits::kMaxAbsTime_s, fallback);
  };
  auto period = [](const TomlReader& t, double fallback) {
    t.Positive("sample_period_s", fallback);
    return t.InRange("sample_period_s", limits::kMinSamplePeriod_s, limits::kMaxAbsTime_s, fallback);
  };
  RunSpec defaults;
  if (const auto d = root.OptionalTable("defaults")) {
    defaults.duration_s = duration(*d, defaults.duration_s);
    defaults.sample_period_s = period(*d, defaults.sample_period_s);
    d->Finish();
  }
  std::set<std::string> ids;
  for (const auto& t : root.ArrayOfTables("runs")) {
    RunSpec run = defaults;
    run.line = t.line();
    run.id = t.String("id");
    if (const std::string why = RunIdProblem(run.id); !why.empty()) {
      t.Fail("id", why + "; run ids must be non-empty, without commas, quotes or control characters, and not start "
                         "with '#' or a space");
    }
    if (!ids.insert(run.id).second) t.Fail("id", fmt::format("run id '{}' is used twice", run.id));
    run.duration_s = duration(t, run.duration_s);
    run.sample_period_s = period(t, run.sample_period_s);
    if (run.sample_period_s > run.duration_s) t.Fail("sample_period_s", "must not exceed duration_s");
    if (run.duration_s / run.sample_period_s > limits::kMaxSamplesPerRun) {
      t.FailHere(fmt::format("duration_s / sample_period_s = {:g} samples; at most {:g} per run (the trace is held in "
                             "memory)", run.duration_s / run.sample_period_s, limits::kMaxSamplesPerRun));
    }
    run.ambient = ReadProfile(t.Table("ambient"), "C", run.duration_s);
    if (const auto power = t.OptionalTable("power")) {
      for (const auto& name : power->Keys()) {
        if (sc.gyro.network.FindSource(name) < 0) power->Fail(name, fmt::format("'{}' is not a heat source of the gyro", name));
        run.power.emplace(name, ReadProfile(power->Table(name), "W", run.duration_s));
      }
      power->Finish();
    }
    if (t.Has("initial_C")) run.initial_C = t.InRange("initial_C", limits::kMinTemperature_C, limits::kMaxTemperature_C);
    for (const auto& src : sc.gyro.network.sources) {
      if (src.driven_by_data && !run.power.count(src.name)) {
        t.FailHere(fmt::format("source '{}' is driven by data: give its power profile in [runs.power.{}]", src.name,
                               src.name));
      }
    }
    t.Finish();
    sc.runs.push_back(std::move(run));
  }
  if (sc.runs.empty()) root.FailHere("a scenario needs at least one [[runs]] entry");
  if (const auto population = root.OptionalTable("population")) {
    sc.population = ReadPopulation(*population);
    (void)Population(*sc.population, sc.gyro);  // its names and correlations refused here, with the file
  }
  root.Finish();
  return sc;
}

}  // namespace rlg::io
