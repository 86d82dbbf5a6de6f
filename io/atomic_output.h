#pragma once
/// Output files written whole or not at all (docs/cli.md, "Output files").
///
/// A file is written under a temporary name beside it, `.<name>.rlgtherm-partial-<pid>`
/// (hidden, and not ending in the output's extension, so that a `*.csv` glob never picks a
/// partial file up), then flushed, fsync()ed, closed and renamed into place; any failure on
/// the way removes the temporary and leaves `path` as it was. A report directory is staged the
/// same way as a whole (`OutputDirectory`). Temporaries are registered for removal on a signal
/// (io/signal_cleanup.h); writes are checked (io/checked_stream.h), which also says which
/// failures are bad usage (exit 2) and which are failed writes (exit 1).

#include <functional>
#include <iosfwd>
#include <memory>
#include <string>
#include <vector>

#include "io/signal_cleanup.h"

namespace rlg::io {

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

}  // namespace rlg::io
