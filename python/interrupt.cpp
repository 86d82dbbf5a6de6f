#include "python/interrupt.h"

#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <pybind11/pybind11.h>
#include <thread>

namespace rlg::python {
namespace py = pybind11;
namespace {

/// Thrown by Interrupt::Check; caught by RunInterruptibly alone (not a std::exception, so no
/// catch of the libraries' takes it for an error of theirs).
struct Interrupted {};

bool OnMainThread() {
  const py::object main = py::module_::import("threading").attr("main_thread")();
  return py::module_::import("threading").attr("get_ident")().equal(main.attr("ident"));
}

}  // namespace

void Interrupt::Check() const {
  if (requested_.load(std::memory_order_relaxed)) throw Interrupted{};
}

void RunInterruptibly(const std::function<void(const Interrupt&)>& work) {
  Interrupt interrupt;
  if (!OnMainThread()) {
    py::gil_scoped_release release;
    work(interrupt);
    return;
  }
  std::mutex m;
  std::condition_variable cv;
  bool done = false;
  std::exception_ptr error;
  std::thread worker([&] {
    try {
      work(interrupt);
    } catch (const Interrupted&) {
      // asked to stop: the signal handler's exception is raised instead
    } catch (...) {
      error = std::current_exception();
    }
    const std::lock_guard<std::mutex> lock(m);
    done = true;
    cv.notify_one();
  });
  bool raised = false;  // a signal handler raised: its exception is set, to be raised at the end
  for (;;) {
    {
      py::gil_scoped_release release;
      std::unique_lock<std::mutex> lock(m);
      // 50 ms: a signal is seen well within a second, and a check costs microseconds.
      if (cv.wait_for(lock, std::chrono::milliseconds(50), [&] { return done; })) break;
    }
    if (!raised && PyErr_CheckSignals() != 0) {
      raised = true;
      interrupt.Request();  // the worker stops at its next check
    }
  }
  worker.join();
  if (raised) throw py::error_already_set();
  if (error) std::rethrow_exception(error);
}

}  // namespace rlg::python
