#pragma once
/// Output files written whole or not at all (docs/cli.md), with every write checked.
///
/// A file is written under a temporary name beside it, `.<name>.rlgtherm-partial-<pid>`
/// (hidden, and not ending in the output's extension, so that a `*.csv` glob never picks a
/// partial file up), then flushed, fsync()ed, closed and renamed into place; any failure on
/// the way removes the temporary and leaves `path` as it was. A report directory is staged the
/// same way as a whole (`OutputDirectory`). Temporaries are registered with a signal handler
/// (`InstallSignalCleanup`) that removes them on SIGINT, SIGTERM and SIGHUP. SIGKILL cannot be
/// caught: a `.*.rlgtherm-partial-<pid>` file or directory found later is the unfinished output
/// of the rlgtherm process <pid>, which was killed; it is safe to delete.
///
/// Errors name the path and the operating system's reason. An output path the system refuses
/// (no such directory, not a directory, permission denied, read-only file system, a directory
/// where a file is wanted) is bad usage: InputError, exit status 2. A write that fails on a
/// usable path (disk full, file size limit, I/O error) is neither usage nor input: OutputError,
/// exit status 1.

#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

namespace rlg::sim {

/// The temporary name of `path` while it is being written: `.<name>.rlgtherm-partial-<pid>` in
/// the same directory (the same file system, so that the final rename is atomic).
std::string PartialName(const std::string& path);

/// Calls write(stream) for `path` and keeps the result whole or not at all: the temporary is
/// renamed into place only when write returns without throwing and every write, the flush,
/// fsync and close succeeded. "-" = stdout, checked after the flush (OutputError if it failed).
/// What is not a regular file is written in place, checked, since a rename would replace it:
/// an existing device or FIFO (-o /dev/null) and descriptor names (/dev/stdout, /dev/stderr,
/// /dev/fd/N, /proc/self/fd/N, bash's >(...)).
void WriteFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

/// Throws OutputError naming standard output and the reason if anything written to stdout
/// (std::cout or C stdio) has failed so far, e.g. `> /dev/full`. Flushes both first.
void CheckStdout();

class FdOutBuf;
/// Standard output as a std::ostream straight onto descriptor 1 (stdio is flushed first), for
/// data: unlike C stdio, it keeps the reason of a failed write for the message.
class StdoutStream {
 public:
  StdoutStream();
  ~StdoutStream();
  StdoutStream(const StdoutStream&) = delete;
  StdoutStream& operator=(const StdoutStream&) = delete;
  std::ostream& stream() { return *stream_; }
  /// Flushes; OutputError naming standard output and the reason if any write failed.
  void Check();

 private:
  std::unique_ptr<FdOutBuf> buf_;
  std::unique_ptr<std::ostream> stream_;
};

/// Installs handlers for SIGINT, SIGTERM and SIGHUP (unless the signal is ignored, as for a
/// background job of a non-interactive shell) that remove the registered temporaries and then
/// re-raise the signal with its default action, so that the exit status still says "killed by
/// signal N". Call once, early in main().
void InstallSignalCleanup();

/// Registers `path` (a file, or an empty-by-then directory: is_dir) for removal by the signal
/// handler while the object lives. Temporaries are removed in reverse order of registration,
/// so files registered after their directory go first.
class TempRegistration {
 public:
  TempRegistration(const std::string& path, bool is_dir = false);
  ~TempRegistration();
  TempRegistration(const TempRegistration&) = delete;
  TempRegistration& operator=(const TempRegistration&) = delete;

 private:
  int slot_;
};

/// A directory of output files (diagnose --report) made whole or not at all. The files are
/// written into a staging directory: `.<name>.rlgtherm-partial-<pid>` beside DIR when DIR does
/// not exist (Commit renames it to DIR), or `.rlgtherm-partial-<pid>` inside an existing DIR
/// (Commit moves each file in, replacing files of the same name and leaving other files alone).
/// Missing parent directories are created, and removed again when nothing is committed.
/// Without Commit (an exception, a signal) nothing of the new report is left.
/// How messages name an OutputDirectory and what it holds: diagnose's report, or the figures
/// of `--plot`.
struct OutputDirectoryNaming {
  std::string option = "--report";   ///< the option that named DIR
  std::string noun = "report";       ///< "cannot create the <noun> directory", "(no <noun> written)"
  std::string file = "report file";  ///< "cannot replace it with a <file>"
};

class OutputDirectory {
 public:
  using Naming = OutputDirectoryNaming;
  /// Creates the staging directory now, so that an unusable DIR is refused (InputError naming
  /// the path and the reason) before any long computation.
  explicit OutputDirectory(std::string dir, Naming naming = {});
  ~OutputDirectory();
  OutputDirectory(const OutputDirectory&) = delete;
  OutputDirectory& operator=(const OutputDirectory&) = delete;

  const std::string& dir() const { return dir_; }
  /// " (no report written)": what a failure leaves, for messages about the staged files.
  std::string NothingWritten() const;
  /// The staging path of file `name` (no '/'), registered for removal on a signal, for writers
  /// that open files themselves (PLplot). The caller checks what they wrote.
  std::string Stage(const std::string& name);
  /// Writes file `name` into the staging directory; every write, flush, fsync and close checked.
  void Write(const std::string& name, const std::function<void(std::ostream&)>& write);
  /// Moves the staged files into DIR (signals held back meanwhile, so that DIR never holds half
  /// a report). The names staged, in order.
  std::vector<std::string> Commit();

 private:
  std::string dir_, staging_;
  Naming naming_;
  bool dir_existed_ = false, committed_ = false;
  std::vector<std::string> created_parents_;  ///< outermost first
  std::vector<std::string> names_;
  std::vector<std::unique_ptr<TempRegistration>> registrations_;  ///< for the signal handler
};

}  // namespace rlg::sim
