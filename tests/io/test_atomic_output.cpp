// Output files are whole or absent: after a failing writer, an unusable path, a file size
// limit (a full disk without root) or a signal, nothing new is left; the message says why.

#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fmt/format.h>
#include <fstream>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include "io/atomic_output.h"
#include "io/signal_cleanup.h"
#include "sim/errors.h"

namespace rlg::io {
namespace {

namespace fs = std::filesystem;

class OutputFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           fmt::format("rlg_out_{}_{}", ::getpid(), ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  /// Every entry under dir_ (hidden ones too), sorted, relative.
  std::vector<std::string> Entries() const {
    std::vector<std::string> out;
    for (const auto& e : fs::recursive_directory_iterator(dir_)) out.push_back(fs::relative(e.path(), dir_).string());
    std::sort(out.begin(), out.end());
    return out;
  }
  std::string Read(const fs::path& p) const {
    std::ifstream in(p);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  /// Runs f in a child process; returns its wait status.
  template <typename F>
  int InChild(F f) {
    const pid_t pid = ::fork();
    if (pid == 0) {
      f();
      ::_exit(0);
    }
    int status = 0;
    ::waitpid(pid, &status, 0);
    return status;
  }
  fs::path dir_;
};

TEST_F(OutputFile, WholeFileAppearsAndNoTemporaryStays) {
  const std::string path = (dir_ / "a.csv").string();
  WriteFileAtomically(path, [](std::ostream& out) { out << "run,t_s\n"; });
  EXPECT_EQ(Read(path), "run,t_s\n");
  EXPECT_EQ(Entries(), std::vector<std::string>{"a.csv"});
}

TEST_F(OutputFile, TemporaryIsHiddenBesideTheOutputAndNamesTheProcess) {
  EXPECT_EQ(PartialName("out.csv"), fmt::format(".out.csv.rlgtherm-partial-{}", ::getpid()));
  EXPECT_EQ(PartialName("/d/e/out.csv"), fmt::format("/d/e/.out.csv.rlgtherm-partial-{}", ::getpid()));
}

TEST_F(OutputFile, WriterThatThrowsLeavesTheOldFileAsItWas) {
  const std::string path = (dir_ / "a.csv").string();
  std::ofstream(path) << "old";
  EXPECT_THROW(WriteFileAtomically(path,
                                   [](std::ostream& out) {
                                     out << "new";
                                     throw InputError("bad data");
                                   }),
               InputError);
  EXPECT_EQ(Read(path), "old");
  EXPECT_EQ(Entries(), std::vector<std::string>{"a.csv"});
}

TEST_F(OutputFile, PathUnderARegularFileIsBadUsageNamingPathAndReason) {
  std::ofstream(dir_ / "file") << "x";
  const std::string path = (dir_ / "file" / "a.csv").string();
  try {
    WriteFileAtomically(path, [](std::ostream& out) { out << "x"; });
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": cannot create the output file: Not a directory"), std::string::npos)
        << e.what();
  }
}

TEST_F(OutputFile, DirectoryAsOutputIsBadUsage) {
  EXPECT_THROW(WriteFileAtomically(dir_.string(), [](std::ostream& out) { out << "x"; }), InputError);
}

// RLIMIT_FSIZE with SIGXFSZ ignored makes writes past the limit fail with EFBIG, as a full
// disk fails them with ENOSPC; set in a child so that this process keeps no limit.
TEST_F(OutputFile, FileSizeLimitIsAnOutputErrorAndLeavesNothing) {
  const std::string path = (dir_ / "big.csv").string();
  const int status = InChild([&] {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit limit{4096, 4096};
    ::setrlimit(RLIMIT_FSIZE, &limit);
    try {
      WriteFileAtomically(path, [](std::ostream& out) {
        for (int i = 0; i < 100000; ++i) out << "0123456789\n";  // 1.1 MB, far past 4 KiB
      });
    } catch (const OutputError& e) {
      const bool named = std::string(e.what()).find(path + ": writing failed: File too large (nothing written)") == 0;
      ::_exit(named ? 42 : 2);
    } catch (...) {
      ::_exit(3);
    }
    ::_exit(1);
  });
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 42) << "42: OutputError naming the file and EFBIG";
  EXPECT_TRUE(Entries().empty());
}

TEST_F(OutputFile, SignalRemovesRegisteredTemporariesAndStillKills) {
  const std::string sub = (dir_ / "staging").string(), file = sub + "/f.png";
  const int status = InChild([&] {
    InstallSignalCleanup();
    TempRegistration d(sub, /*is_dir=*/true);
    fs::create_directory(sub);
    TempRegistration f(file);
    std::ofstream(file) << "partial";
    ::raise(SIGTERM);
    ::_exit(1);  // not reached: the handler re-raises with the default action
  });
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit status " << status;
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_TRUE(Entries().empty());
}

TEST_F(OutputFile, UncommittedReportLeavesNothingNotEvenCreatedParents) {
  {
    OutputDirectory report((dir_ / "a" / "b" / "report").string());
    report.Write("x.json", [](std::ostream& out) { out << "{}"; });
  }
  EXPECT_TRUE(Entries().empty());
}

TEST_F(OutputFile, NewReportAppearsWhole) {
  OutputDirectory report((dir_ / "report").string());
  report.Write("x.json", [](std::ostream& out) { out << "{}"; });
  report.Stage("never-drawn.png");  // a figure with nothing to draw is skipped
  const std::string staging = PartialName("report");
  EXPECT_EQ(Entries(), (std::vector<std::string>{staging, staging + "/x.json"}));
  EXPECT_EQ(report.Commit(), std::vector<std::string>{"x.json"});
  EXPECT_EQ(Entries(), (std::vector<std::string>{"report", "report/x.json"}));
}

TEST_F(OutputFile, ReportIntoAnExistingDirectoryReplacesItsFilesAndKeepsOthers) {
  fs::create_directory(dir_ / "report");
  std::ofstream(dir_ / "report" / "x.json") << "old";
  std::ofstream(dir_ / "report" / "notes.txt") << "mine";
  {
    OutputDirectory failed((dir_ / "report").string());
    failed.Write("x.json", [](std::ostream& out) { out << "half"; });
  }  // not committed: as it was
  EXPECT_EQ(Read(dir_ / "report" / "x.json"), "old");
  OutputDirectory report((dir_ / "report").string());
  report.Write("x.json", [](std::ostream& out) { out << "new"; });
  report.Commit();
  EXPECT_EQ(Read(dir_ / "report" / "x.json"), "new");
  EXPECT_EQ(Entries(), (std::vector<std::string>{"report", "report/notes.txt", "report/x.json"}));
}

TEST_F(OutputFile, ReportUnderARegularFileIsBadUsageNamingTheFile) {
  std::ofstream(dir_ / "file") << "x";
  try {
    OutputDirectory report((dir_ / "file" / "report").string());
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is a file): Not a directory"), std::string::npos) << e.what();
  }
  EXPECT_EQ(Entries(), std::vector<std::string>{"file"});
}

}  // namespace
}  // namespace rlg::io
