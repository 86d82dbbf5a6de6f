// Plug-in compensators (validation/plugin.h): the output formats, and running a command with
// a run on its stdin, on small commands of the shell.

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <future>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <unistd.h>

#include "sim/errors.h"
#include "validation/plugin.h"

namespace rlg::validation {

namespace {

sim::Run SmallRun(size_t n) {
  sim::Run r;
  r.id = "r";
  auto& T1 = r.AddColumn("T1");
  auto& b = r.AddColumn("bias_dph");
  for (size_t k = 0; k < n; ++k) {
    r.t_s.push_back(static_cast<double>(k));
    T1.push_back(20.0 + 0.01 * static_cast<double>(k));
    b.push_back(0.5 + 0.001 * static_cast<double>(k));
  }
  return r;
}

/// The message of the InputError f throws ("" if none).
template <typename F>
std::string Refusal(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PluginOutput, ReadsOneNumberPerLineSkippingCommentsAndBlankLines) {
  EXPECT_EQ(ParsePluginOutput("# mine\n1.5\n\n-2e-3\r\n 3 \n", 3, "compensated_dph", "p"),
            (std::vector<double>{1.5, -2e-3, 3.0}));
}

TEST(PluginOutput, ReadsTheNamedColumnOfACsv) {
  EXPECT_EQ(ParsePluginOutput("run,compensated_dph,x\na,1,9\na,2,9\n", 2, "compensated_dph", "p"),
            (std::vector<double>{1.0, 2.0}));
  EXPECT_EQ(ParsePluginOutput("mine\n4\n", 1, "mine", "p"), (std::vector<double>{4.0}));
}

TEST(PluginOutput, RefusesAWrongCountNonNumbersAndAMissingColumnNamingTheLine) {
  EXPECT_EQ(Refusal([] { ParsePluginOutput("1\n2\n", 3, "c", "compensator 'p'"); }),
            "compensator 'p': wrote 2 values for the 3 rows it was given (one per row expected)");
  EXPECT_EQ(Refusal([] { ParsePluginOutput("1\nnan\n", 2, "c", "p"); }),
            "p: output line 2: expected a finite number, found 'nan'");
  EXPECT_EQ(Refusal([] { ParsePluginOutput("1\n2x\n", 2, "c", "p"); }), "p: output line 2: expected a finite number, found '2x'");
  EXPECT_EQ(Refusal([] { ParsePluginOutput("a,b\n1,2\n", 1, "c", "p"); }),
            "p: output line 1: expected a number or a CSV header naming column 'c', found 'a,b'");
  EXPECT_EQ(Refusal([] { ParsePluginOutput("a,c\n1\n", 1, "c", "p"); }), "p: output line 2: 1 fields, the header has 2");
  EXPECT_EQ(Refusal([] { ParsePluginOutput("c\ninf\n", 1, "c", "p"); }),
            "p: output line 2: expected a finite number in column 'c', found 'inf'");
}

TEST(Plugin, GetsTheRunAsTidyCsvOnStdin) {
  PluginCompensator p;
  p.name = "echo-bias";
  p.command = "tail -n +2 | cut -d, -f4";  // run,t_s,T1,bias_dph: the bias unchanged
  const sim::Run run = SmallRun(5);
  EXPECT_EQ(RunPlugin(p, run), run.Column("bias_dph"));  // 6-decimal values, written exactly
}

TEST(Plugin, ALargeRunPassesWithoutDeadlock) {
  // More than a pipe's buffer (64 KiB) each way: writing and reading interleave.
  PluginCompensator p;
  p.name = "cat";
  p.command = "tail -n +2 | cut -d, -f4";
  const sim::Run run = SmallRun(20000);
  EXPECT_EQ(RunPlugin(p, run).size(), run.size());
}

TEST(Plugin, ANonzeroExitOrASignalIsAnInputErrorWithItsStderr) {
  PluginCompensator p;
  p.name = "broken";
  p.command = "echo no model here >&2; exit 3";  // exits without reading its input
  EXPECT_EQ(Refusal([&] { RunPlugin(p, SmallRun(100000)); }),
            "compensator 'broken' (`echo no model here >&2; exit 3`) on run 'r': exited with status 3; its stderr ends: "
            "no model here");
  p.command = "kill -9 $$";
  EXPECT_EQ(Refusal([&] { RunPlugin(p, SmallRun(3)); }), "compensator 'broken' (`kill -9 $$`) on run 'r': killed by signal 9");
  p.command = "no-such-command-rlgtherm";
  EXPECT_NE(Refusal([&] { RunPlugin(p, SmallRun(3)); }).find("exited with status 127; its stderr ends: "), std::string::npos);
}

TEST(Plugin, RunsInItsDirectory) {
  PluginCompensator p;
  p.name = "pwd";
  p.directory = "/";
  p.command = "cat > /dev/null; [ \"$(pwd)\" = / ] && echo 1 && echo 2";
  EXPECT_EQ(RunPlugin(p, SmallRun(2)), (std::vector<double>{1.0, 2.0}));
}

TEST(Plugin, GetsOnlyStandardDescriptorsNotAnotherPluginsPipes) {
  // One plug-in holds its pipes open (it waits for a file) while a second, started meanwhile on
  // another thread as a population's gyros are, lists the descriptors of its shell: 0, 1 and 2
  // alone. Before, it held the first one's pipes too (and any the host had opened), so a
  // plug-in's stdin or stdout ended only when every plug-in started after it had exited.
  const auto dir = std::filesystem::temp_directory_path() / fmt::format("rlg_plugin_fds_{}", ::getpid());
  std::filesystem::create_directories(dir);
  PluginCompensator waiting;
  waiting.name = "waiting";
  waiting.directory = dir.string();
  waiting.command = "cat > /dev/null; touch started; while [ ! -e go ]; do sleep 0.01; done; echo 1";
  auto first = std::async(std::launch::async, [&] { return RunPlugin(waiting, SmallRun(1)); });
  // Until it has read its input (at most 30 s: a loaded machine; the test fails, not hangs).
  for (int k = 0; k < 3000 && !std::filesystem::exists(dir / "started"); ++k) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(std::filesystem::exists(dir / "started"));
  PluginCompensator lister;
  lister.name = "lister";
  lister.command = "cat > /dev/null; ls /proc/$$/fd";  // the shell's descriptors, one per line
  std::vector<double> fds;
  // Three descriptors are three values for the three rows; more are a refusal that counts them.
  const std::string refusal = Refusal([&] { fds = RunPlugin(lister, SmallRun(3)); });
  std::ofstream(dir / "go").put('\n');  // before any assertion: the first plug-in ends
  EXPECT_EQ(first.get(), (std::vector<double>{1.0}));
  std::filesystem::remove_all(dir);
  EXPECT_EQ(refusal, "");
  EXPECT_EQ(fds, (std::vector<double>{0.0, 1.0, 2.0}));
}

}  // namespace
}  // namespace rlg::validation
