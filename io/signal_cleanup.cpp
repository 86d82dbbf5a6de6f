#include "io/signal_cleanup.h"

#include <atomic>
#include <cerrno>
#include <climits>
#include <csignal>
#include <cstring>
#include <fmt/format.h>
#include <stdexcept>
#include <unistd.h>

#include "io/checked_stream.h"

namespace rlg::io {
namespace {

/// Registered temporaries. The handler only reads slots whose state is kLive; a slot is filled
/// while kBusy, so that a signal arriving during (un)registration never sees half a path.
// A report holds a handful of files; --plot two figures per run (validate: per run and
// compensator): 256 slots (1 MiB of paths) leave room for ~120 runs in one figure directory.
constexpr int kSlots = 256;
enum SlotState : int { kFree = 0, kBusy = 1, kLive = 2 };
struct Slot {
  std::atomic<int> state{kFree};
  unsigned long seq = 0;  // registration order: the handler removes the newest first
  bool is_dir = false;
  char path[PATH_MAX] = {};
};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler reads slot states");
Slot g_slots[kSlots];
// Registrations come from any thread (populations write figures on theirs; Python releases the
// GIL around writes): the counter is atomic, each registration gets a number of its own.
std::atomic<unsigned long> g_next_seq{1};
const int kCleanupSignals[] = {SIGINT, SIGTERM, SIGHUP};

extern "C" void CleanupAndReraise(int sig) {
  // Only async-signal-safe calls here: unlink, rmdir, raise.
  unsigned long below = ULONG_MAX;
  while (true) {
    int newest = -1;
    for (int i = 0; i < kSlots; ++i) {
      if (g_slots[i].state.load() == kLive && g_slots[i].seq < below &&
          (newest < 0 || g_slots[i].seq > g_slots[newest].seq)) {
        newest = i;
      }
    }
    if (newest < 0) break;
    below = g_slots[newest].seq;
    if (g_slots[newest].is_dir) {
      ::rmdir(g_slots[newest].path);
    } else {
      ::unlink(g_slots[newest].path);
    }
  }
  // SA_RESETHAND restored the default action; the signal stays blocked until this handler
  // returns, and is then delivered again and ends the process as "killed by signal".
  ::raise(sig);
}

}  // namespace

SignalHold::SignalHold() {
  sigset_t set;
  sigemptyset(&set);
  for (int s : kCleanupSignals) sigaddset(&set, s);
  sigprocmask(SIG_BLOCK, &set, &old_);
}

SignalHold::~SignalHold() { sigprocmask(SIG_SETMASK, &old_, nullptr); }

TempRegistration::TempRegistration(const std::string& path, bool is_dir) : slot_(-1) {
  if (path.size() >= PATH_MAX) ThrowOsError(path, "cannot create the output file", ENAMETOOLONG);
  for (int i = 0; i < kSlots; ++i) {
    int expected = kFree;
    if (g_slots[i].state.compare_exchange_strong(expected, kBusy)) {
      slot_ = i;
      break;
    }
  }
  if (slot_ < 0) throw std::logic_error(fmt::format("TempRegistration: more than {} temporaries at once", kSlots));
  Slot& s = g_slots[slot_];
  std::memcpy(s.path, path.c_str(), path.size() + 1);
  s.is_dir = is_dir;
  s.seq = g_next_seq.fetch_add(1);
  s.state.store(kLive);
}

TempRegistration::~TempRegistration() { g_slots[slot_].state.store(kFree); }

void InstallSignalCleanup() {
  for (int sig : kCleanupSignals) {
    struct sigaction old {};
    if (sigaction(sig, nullptr, &old) != 0 || old.sa_handler == SIG_IGN) continue;
    struct sigaction sa {};
    sa.sa_handler = CleanupAndReraise;
    sigemptyset(&sa.sa_mask);
    for (int s : kCleanupSignals) sigaddset(&sa.sa_mask, s);  // one cleanup at a time
    sa.sa_flags = SA_RESETHAND;
    sigaction(sig, &sa, nullptr);
  }
}

}  // namespace rlg::io
