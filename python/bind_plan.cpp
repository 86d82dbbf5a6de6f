// Calibration plans (docs/plan.md): plan, plan_count, plan_gyros and plan_merge over validation/plan.h. A
// shard is the dict plan_gyros returns, the JSON of `rlgtherm plan PLAN --gyros FROM:TO`, so
// gyros run anywhere (processes, Dask workers: rlgtherm_dask.run_plan) and plan_merge turns the
// shards, in any order, into the dict of `rlgtherm plan PLAN --json`.

#include <fmt/format.h>
#include <pybind11/stl.h>

#include "python/bindings.h"
#include "python/convert.h"
#include "python/interrupt.h"
#include "sim/errors.h"
#include "validation/plan.h"
#include "validation/plan_spec.h"

namespace rlg::python {
namespace {

/// A shard dict as the JSON the CLI's --merge reads: through Python's json module, whose float
/// repr is the shortest round trip, so every double comes back with its bits.
nlohmann::json JsonOf(const py::handle& shard) {
  const std::string text = py::module_::import("json").attr("dumps")(shard).cast<std::string>();
  return nlohmann::json::parse(text);
}

}  // namespace

void BindPlan(py::module_& m) {
  m.def(
      "plan_count",
      [](const py::object& plan) { return validation::LoadPlan(PathOf(plan)).gyros; }, py::arg("plan"),
      "The number of gyros a plan file simulates (its `gyros`, or [population] count).");
  m.def(
      "plan",
      [](const py::object& plan, int threads, uint64_t verify) {
        CheckThreads(threads);
        const validation::Planner planner(validation::LoadPlan(PathOf(plan)));
        nlohmann::json j;
        RunInterruptibly([&](const Interrupt& interrupt) {
          j = validation::PlanJson(planner, planner.Run(threads, verify, [&] { interrupt.Check(); }));
        });
        return py::dict(ToPython(j));
      },
      py::arg("plan"), py::arg("threads") = 0, py::arg("verify") = 0,
      R"(Every candidate protocol of a plan file through calibrate, fit and compensate on every gyro,
as `rlgtherm plan PLAN --json [--verify N]` (docs/plan.md): a dict with candidates (name,
chamber_h, p95_abs_bias_after_dph, p95_interval_dph, ...), recommended, answer and, with
verify > 0, verify. threads: 0 for one per core. Releases the GIL; Ctrl-C stops it between gyros
(KeyboardInterrupt).)");
  m.def(
      "plan_gyros",
      [](const py::object& plan, uint64_t first, uint64_t count, int threads) {
        CheckThreads(threads);
        const validation::Planner planner(validation::LoadPlan(PathOf(plan)));
        const uint64_t gyros = planner.spec().gyros;
        if (count == 0 || first >= gyros || count > gyros - first) {
          throw InputError(fmt::format("gyros {} .. {}: expected a range within 0 .. {} (the plan's gyros)", first,
                                       first + count - 1, gyros - 1));
        }
        nlohmann::json j;
        RunInterruptibly([&](const Interrupt& interrupt) {
          j = validation::ShardJson(planner, planner.Simulate(first, count, threads, [&] { interrupt.Check(); }));
        });
        return py::dict(ToPython(j));
      },
      py::arg("plan"), py::arg("first"), py::arg("count"), py::arg("threads") = 1,
      R"(Gyros first .. first + count - 1 of a plan through its candidates: a shard, the dict of
`rlgtherm plan PLAN --gyros FROM:TO` (FROM = first, TO = first + count). plan_merge takes
the shards. Releases the GIL; Ctrl-C stops it between gyros (KeyboardInterrupt).)");
  m.def(
      "plan_merge",
      [](const py::object& plan, const py::list& shards, int threads, uint64_t verify) {
        CheckThreads(threads);
        const validation::Planner planner(validation::LoadPlan(PathOf(plan)));
        std::vector<std::pair<std::string, nlohmann::json>> parts;
        for (size_t i = 0; i < shards.size(); ++i) {
          parts.emplace_back(fmt::format("shard {}", i), JsonOf(shards[i]));
        }
        nlohmann::json j;
        RunInterruptibly([&](const Interrupt& interrupt) {
          j = validation::PlanJson(planner, planner.Conclude(validation::MergeShards(planner, parts), threads, verify,
                                                             [&] { interrupt.Check(); }));
        });
        return py::dict(ToPython(j));
      },
      py::arg("plan"), py::arg("shards"), py::arg("threads") = 0, py::arg("verify") = 0,
      R"(The shards of plan_gyros, in any order, covering every gyro once, as the dict plan(plan)
returns (`rlgtherm plan PLAN --merge SHARD..`); ValueError naming the shard (its index) for one
of another plan, a gyro in two shards or in none.)");
}

}  // namespace rlg::python
