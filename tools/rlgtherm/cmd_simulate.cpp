#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <memory>
#include <unistd.h>

#include "io/csv.h"
#include "io/npz.h"
#include "io/scenario_file.h"
#include "sim/errors.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "sim/stats.h"
#include "tools/rlgtherm/commands.h"

namespace rlg::cli {

int RunSimulate(const SimulateArgs& a) {
  sim::Scenario sc = io::LoadScenario(a.scenario);
  uint64_t seed = a.seed.value_or(sc.seed);
  if (sc.population && !a.gyro) {
    throw InputError(fmt::format("{}: the scenario has a [population] of {} gyros: give --gyro I (0 ... {})", a.scenario,
                                 sc.population->count, sc.population->count - 1));
  }
  if (a.gyro) {
    if (!sc.population) throw InputError(fmt::format("{}: --gyro needs a [population] in the scenario", a.scenario));
    seed = sim::UsePopulationGyro(sc, seed, *a.gyro);  // drawn from the seed and I, simulated with its own seed
  }
  const bool tty = ::isatty(STDERR_FILENO);
  const sim::Trace trace = sim::SimulateScenario(sc, seed, [&](size_t i, size_t n) {
    if (tty) fmt::print(stderr, "\rsimulating run {}/{} ({})\x1b[K", i + 1, n, sc.runs[i].id);
  });
  if (tty) fmt::print(stderr, "\r\x1b[K");
  sim::CheckReadable(sc, trace);
  // A name ending in .npz gets numpy's binary arrays (io/npz.h), anything else the tidy CSV.
  const bool npz = a.out.size() > 4 && a.out.compare(a.out.size() - 4, 4, ".npz") == 0;
  io::WriteFileAtomically(a.out, [&](std::ostream& out) {
    if (npz) {
      io::WriteTraceNpz(trace, out);
    } else {
      io::WriteTraceCsv(trace, out);
    }
  });
  if (a.out == "-") return 0;  // stdout carries the data
  fmt::print("{} runs of gyro '{}'{} -> {} (seed {})\n", trace.runs.size(), sc.gyro.name,
             a.gyro ? fmt::format(", population gyro {}", *a.gyro) : "", a.out, seed);
  fmt::print("{:<14} {:>9} {:>8} {:>8} {:>8} {:>10} {:>10}\n", "run", "samples", "T_amb0", "dT1", "dT2", "mean_dph",
             "sigma_dph");
  for (const auto& r : trace.runs) {
    const auto& t1 = r.Column("T1");
    // A gyro without an anode sensor has no dT2: shown as "-", never as a printed nan.
    const std::string dT2 = r.Has("T2") ? fmt::format("{:.3f}", r.Column("T2").back() - r.Column("T2").front()) : "-";
    fmt::print("{:<14} {:>9} {:>8.2f} {:>8.3f} {:>8} {:>10.4f} {:>10.4f}\n", r.id, r.size(), r.Column("T_amb").front(),
               t1.back() - t1.front(), dT2, sim::Mean(r.Column("bias_dph")), sim::StdDev(r.Column("bias_dph")));
  }
  return 0;
}

Verb RegisterSimulate(CLI::App& app) {
  auto a = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "simulate the runs of a scenario file into the tidy CSV run,t_s,T_amb,T1..T4,bias_dph (docs/data-format.md)");
  cmd->add_option("SCENARIO", a->scenario,
                  "scenario TOML file (scenarios/README.md; a validate suite goes to validate)")
      ->required();
  cmd->add_option("--seed", a->seed, "random seed (default: the scenario's 'seed', else 1)");
  cmd->add_option("-o,--output", a->out, "output file: tidy CSV, or numpy's .npz when it ends in .npz ('-' = stdout)");
  cmd->add_option("--gyro", a->gyro,
                  "gyro I of the scenario's [population] (scenarios/README.md): its drawn "
                  "parameters and its seed, the same gyro as in a population suite");
  return {cmd, [a] { return RunSimulate(*a); }};
}

}  // namespace rlg::cli
