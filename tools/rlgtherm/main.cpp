// rlgtherm: the command line. Thin by design: parse, call the libraries, print.
// Exit status (SPEC section 3): 0 ok, 1 internal error, 2 bad usage or input, 3 numerical failure.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fmt/format.h>
#include <iostream>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "sim/csv.h"
#include "sim/errors.h"
#include "sim/scenario.h"
#include "sim/simulator.h"
#include "sim/stats.h"

namespace {

using namespace rlg;

struct SimulateArgs {
  std::string scenario;
  std::optional<uint64_t> seed;
  std::string out = "-";
};

int RunSimulate(const SimulateArgs& a) {
  const sim::Scenario sc = sim::LoadScenario(a.scenario);
  const uint64_t seed = a.seed.value_or(sc.seed);
  const bool tty = ::isatty(STDERR_FILENO);
  const sim::Trace trace = sim::SimulateScenario(sc, seed, [&](size_t i, size_t n) {
    if (tty) fmt::print(stderr, "\rsimulating run {}/{} ({})\x1b[K", i + 1, n, sc.runs[i].id);
  });
  if (tty) fmt::print(stderr, "\r\x1b[K");
  sim::WriteFileAtomically(a.out, [&](std::ostream& out) { sim::WriteTraceCsv(trace, out); });
  if (a.out == "-") return 0;  // stdout carries the data
  fmt::print("{} runs of gyro '{}' -> {} (seed {})\n", trace.runs.size(), sc.gyro.name, a.out, seed);
  fmt::print("{:<14} {:>9} {:>8} {:>8} {:>8} {:>10} {:>10}\n", "run", "samples", "T_amb0", "dT1", "dT2", "mean_dph",
             "sigma_dph");
  for (const auto& r : trace.runs) {
    const auto& t1 = r.Column("T1");
    const double dT2 = r.Has("T2") ? r.Column("T2").back() - r.Column("T2").front() : NAN;
    fmt::print("{:<14} {:>9} {:>8.2f} {:>8.3f} {:>8.3f} {:>10.4f} {:>10.4f}\n", r.id, r.size(), r.Column("T_amb").front(),
               t1.back() - t1.front(), dT2, sim::Mean(r.Column("bias_dph")), sim::StdDev(r.Column("bias_dph")));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"rlgtherm: simulate and compensate the thermal bias of ring laser gyroscopes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rlgtherm 0.1.0");

  SimulateArgs sim_args;
  auto* simulate = app.add_subcommand("simulate", "simulate a scenario suite into the tidy CSV (SPEC section 2)");
  simulate->add_option("SCENARIO", sim_args.scenario, "scenario TOML file")->required();
  simulate->add_option("--seed", sim_args.seed, "random seed (default: the scenario's 'seed', else 1)");
  simulate->add_option("-o,--output", sim_args.out, "output CSV ('-' = stdout)");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  try {
    if (simulate->parsed()) return RunSimulate(sim_args);
  } catch (const InputError& e) {
    fmt::print(stderr, "rlgtherm: error: {}\n", e.what());
    return 2;
  } catch (const NumericalError& e) {
    fmt::print(stderr, "rlgtherm: numerical failure: {}\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    fmt::print(stderr, "rlgtherm: internal error: {}\n", e.what());
    return 1;
  }
  return 1;
}
