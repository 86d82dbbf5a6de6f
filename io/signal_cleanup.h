#pragma once
/// Temporaries removed when the process is interrupted. Output files are written under a
/// temporary name and renamed into place (io/atomic_output.h); the temporaries are registered
/// here, and a handler for SIGINT, SIGTERM and SIGHUP removes them before the signal ends the
/// process. SIGKILL cannot be caught: a `.*.rlgtherm-partial-<pid>` file or directory found
/// later is the unfinished output of the rlgtherm process <pid>, which was killed; it is safe
/// to delete. The handler makes only async-signal-safe calls (unlink, rmdir, raise).

#include <csignal>
#include <string>

namespace rlg::io {

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

/// Holds back the cleanup signals while it lives (a commit that must not stop half-way); they
/// are delivered when it ends.
class SignalHold {
 public:
  SignalHold();
  ~SignalHold();
  SignalHold(const SignalHold&) = delete;
  SignalHold& operator=(const SignalHold&) = delete;

 private:
  sigset_t old_;
};

}  // namespace rlg::io
