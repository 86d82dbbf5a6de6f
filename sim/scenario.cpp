#include "sim/scenario.h"

#include <filesystem>
#include <fmt/format.h>
#include <set>
#include <toml++/toml.h>

#include "sim/errors.h"
#include "sim/toml_reader.h"

namespace rlg::sim {

Profile ReadProfile(const TomlReader& t, const std::string& u) {
  const std::string kind = t.String("profile");
  try {
    Profile p = Profile::Constant(0.0);
    if (kind == "constant") {
      p = Profile::Constant(t.Number("value_" + u));
    } else if (kind == "ramp") {
      p = Profile::Ramp(t.Number("start_" + u), t.Number("rate_" + u + "_per_min") / 60.0, t.Number("start_s", 0.0),
                        t.Number("end_" + u));
    } else if (kind == "table") {
      p = Profile::Table(t.Pairs("points"));
    } else if (kind == "steps") {
      p = Profile::Steps(t.Number("initial_" + u), t.Pairs("steps"));
    } else if (kind == "sine") {
      p = Profile::Sine(t.Number("mean_" + u), t.Number("amplitude_" + u), t.Number("period_s"),
                        t.Number("phase_deg", 0.0) * M_PI / 180.0);
    } else {
      t.Fail("profile", fmt::format("unknown profile '{}'; expected constant, ramp, table, steps or sine", kind));
    }
    t.Finish();
    return p;
  } catch (const std::invalid_argument& e) {
    t.FailHere(e.what());
  }
}

Scenario LoadScenario(const std::string& path) {
  if (!std::filesystem::is_regular_file(path)) {
    throw InputError(fmt::format("{}: scenario file not found (expected a TOML scenario, see scenarios/README.md)", path));
  }
  const auto doc = ParseTomlFile(path);
  const TomlReader root(*doc, path, "scenario");
  Scenario sc;
  sc.path = path;
  const std::string gyro_rel = root.String("gyro");
  const std::filesystem::path gyro_path = std::filesystem::path(path).parent_path() / gyro_rel;
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

  if (const auto solver = root.OptionalTable("solver")) {
    const std::string method = solver->String("method", "auto");
    if (method == "auto") {
      sc.solver.method = ThermalMethod::kAuto;
    } else if (method == "cvode") {
      sc.solver.method = ThermalMethod::kCvode;
    } else if (method == "exact") {
      sc.solver.method = ThermalMethod::kExactLinear;
    } else {
      solver->Fail("method", "expected \"auto\", \"cvode\" or \"exact\"");
    }
    IntegratorOptions& cv = sc.solver.cvode;
    cv.rtol = solver->Number("rtol", cv.rtol);
    cv.atol = solver->Number("atol_C", cv.atol);
    cv.max_steps = solver->Integer("max_steps", cv.max_steps);
    cv.max_step_s = solver->Number("max_step_s", cv.max_step_s);
    std::string why;
    if (!cv.IsValid(&why)) solver->FailHere(why);
    solver->Finish();
  }
  RunSpec defaults;
  if (const auto d = root.OptionalTable("defaults")) {
    defaults.duration_s = d->Positive("duration_s", defaults.duration_s);
    defaults.sample_period_s = d->Positive("sample_period_s", defaults.sample_period_s);
    d->Finish();
  }
  std::set<std::string> ids;
  for (const auto& t : root.ArrayOfTables("runs")) {
    RunSpec run = defaults;
    run.id = t.String("id");
    if (run.id.empty() || run.id.find_first_of(",\n\"") != std::string::npos) {
      t.Fail("id", "run ids must be non-empty and contain no commas, quotes or newlines");
    }
    if (!ids.insert(run.id).second) t.Fail("id", fmt::format("run id '{}' is used twice", run.id));
    run.duration_s = t.Positive("duration_s", run.duration_s);
    run.sample_period_s = t.Positive("sample_period_s", run.sample_period_s);
    if (run.sample_period_s > run.duration_s) t.Fail("sample_period_s", "must not exceed duration_s");
    run.ambient = ReadProfile(t.Table("ambient"), "C");
    if (const auto power = t.OptionalTable("power")) {
      for (const auto& name : power->Keys()) {
        if (sc.gyro.network.FindSource(name) < 0) power->Fail(name, fmt::format("'{}' is not a heat source of the gyro", name));
        run.power.emplace(name, ReadProfile(power->Table(name), "W"));
      }
      power->Finish();
    }
    if (t.Has("initial_C")) run.initial_C = t.Number("initial_C");
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
  root.Finish();
  return sc;
}

}  // namespace rlg::sim
