// rlgtherm: the command line. Thin by design: parse, call the libraries, print.
// Exit status (docs/cli.md): 0 ok, 1 internal error or an output that could not be written
// (disk full, I/O error), 2 bad usage or input (an output path the system refuses is usage),
// 3 numerical failure; `validate` adds 4: the checks ran and at least one failed; `plan` adds
// 4: no candidate meets the target, or --verify's realised p95 disagrees with the prediction.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <functional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "io/checked_stream.h"
#include "io/process_memory.h"
#include "io/signal_cleanup.h"
#include "sim/errors.h"
#include "sim/simd.h"
#include "tools/rlgtherm/commands.h"

namespace {

/// Bad usage, with the prefix of every other refusal (docs/cli.md, "Exit statuses"): the verb's
/// --help named, an unknown or missing verb answered with the list of verbs. Exit status 2.
int UsageError(const CLI::App& app, const CLI::ParseError& e, int argc, char** argv) {
  std::vector<std::string> verbs;
  for (const auto* v : app.get_subcommands([](const CLI::App*) { return true; })) verbs.push_back(v->get_name());
  std::string message = e.what(), verb;
  for (const auto& v : verbs)
    if (argc >= 2 && v == argv[1]) verb = v;
  if (verb.empty() && (argc < 2 || std::string_view(argv[1]).rfind('-', 0) != 0)) {
    message = argc < 2 ? "expected a verb" : fmt::format("unknown verb '{}'", argv[1]);
    message += fmt::format("; the verbs are {}", fmt::join(verbs, ", "));
  }
  fmt::print(stderr, "rlgtherm: error: {} (rlgtherm{} --help)\n", message, verb.empty() ? "" : " " + verb);
  return 2;
}

/// Runs a verb and maps what it throws to the exit statuses of docs/cli.md: 2 bad input,
/// 3 numerical failure, 1 an output not written or an internal error.
int RunVerb(const std::function<int()>& run) {
  try {
    const int status = run();
    rlg::io::CheckStdout();  // a summary or data lost on a full disk or closed pipe is a failure
    return status;
  } catch (const rlg::InputError& e) {
    fmt::print(stderr, "rlgtherm: error: {}\n", e.what());
    return 2;
  } catch (const rlg::NumericalError& e) {
    fmt::print(stderr, "rlgtherm: numerical failure: {}\n", e.what());
    return 3;
  } catch (const rlg::OutputError& e) {
    fmt::print(stderr, "rlgtherm: error: {}\n", e.what());
    return 1;
  } catch (const std::system_error& e) {
    // fmt::print throws this when stdout does not take the text (disk full, closed pipe).
    if (std::ferror(stdout)) {
      fmt::print(stderr, "rlgtherm: error: standard output: writing failed: {}\n", e.code().message());
    } else {
      fmt::print(stderr, "rlgtherm: internal error: {}\n", e.what());
    }
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "rlgtherm: internal error: {}\n", e.what());
    return 1;
  }
}

}  // namespace

int main(int argc, char** argv) {
  rlg::io::InstallSignalCleanup();  // no partial output files left behind by Ctrl-C or kill
  rlg::io::KeepFreedMemory();      // reuse freed memory: a population's gyros page-fault less (process_memory.h)
#if defined(RLG_AVX2_DISPATCH)
  rlg::sim::UseAvx2();  // RLG_SIMD read now, before any thread runs (sim/simd.h)
#endif
  CLI::App app{"rlgtherm: simulate and compensate the thermal bias of ring laser gyroscopes"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "rlgtherm " RLG_VERSION);  // CMakeLists.txt project(... VERSION)
  std::vector<rlg::cli::Verb> verbs;
  for (const auto add : rlg::cli::kVerbs) verbs.push_back(add(app));
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    return UsageError(app, e, argc, argv);
  }
  for (const auto& verb : verbs)
    if (verb.command->parsed()) return RunVerb(verb.run);
  return RunVerb([] { return 1; });  // require_subcommand(1): not reached
}
