#pragma once
// Ctrl-C during a long call (docs/python.md, "Copies, views and threads"). Python handles a signal
// on its main thread only, with the GIL, between bytecodes: a call that runs C++ for seconds
// without the GIL would see SIGINT only when it returns. RunInterruptibly runs such a call on a
// second thread while the main thread checks for signals; the call checks an Interrupt between
// its pieces (gyros, runs) and stops there, so nothing is left half made.

#include <atomic>
#include <functional>

namespace rlg::python {

/// Set once the caller's signal handler raised (SIGINT: KeyboardInterrupt); read from any thread.
class Interrupt {
 public:
  /// Throws (an exception of RunInterruptibly's own) once a signal handler has raised: call it
  /// between two pieces of work, from any thread; what it aborts is discarded.
  void Check() const;
  void Request() { requested_.store(true, std::memory_order_relaxed); }

 private:
  std::atomic<bool> requested_{false};
};

/// Runs `work` without the GIL; call with the GIL held. On Python's main thread `work` runs on a
/// second thread while this one runs Python's signal handlers every 50 ms (PyErr_CheckSignals);
/// when one raises, `work` is asked to stop (Interrupt::Check), and once it has, that exception
/// (KeyboardInterrupt for SIGINT) is raised instead of `work`'s result or error. On any other
/// thread (signals are handled on the main thread only) `work` runs on this thread.
void RunInterruptibly(const std::function<void(const Interrupt&)>& work);

}  // namespace rlg::python
