#include "validation/parallel.h"

#include <algorithm>
#include <thread>

#ifdef RLG_TSAN
#include <condition_variable>
#include <exception>
#include <mutex>
#else
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>
#endif

namespace rlg::validation {

int LoopThreads(int threads) {
  return threads > 0 ? threads : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

uint64_t PipelineTokens(int threads) { return 2 * static_cast<uint64_t>(LoopThreads(threads)); }

#ifndef RLG_TSAN

// oneTBB: an arena of t threads, the caller one of them. TBB caps its workers at the core count
// less one and warns on stderr when an arena asks for more; lift the cap to t.

namespace {

void ForOnThreads(uint64_t n, int t, const std::function<void(uint64_t)>& body) {
  const tbb::global_control cap(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(t));
  tbb::task_arena arena(t);
  arena.execute([&] {
    tbb::parallel_for(tbb::blocked_range<uint64_t>(0, n, 1), [&](const tbb::blocked_range<uint64_t>& r) {
      for (uint64_t i = r.begin(); i < r.end(); ++i) body(i);
    });
  });
}

void PipelineOnThreads(uint64_t n, int t, const std::function<void(uint64_t)>& compute,
                       const std::function<void(uint64_t)>& consume) {
  const tbb::global_control cap(tbb::global_control::max_allowed_parallelism, static_cast<size_t>(t));
  tbb::task_arena arena(t);
  arena.execute([&] {
    uint64_t next = 0;
    // The token count bounds the indices between input and the end of the in-order consume.
    tbb::parallel_pipeline(static_cast<size_t>(PipelineTokens(t)),
                           tbb::make_filter<void, uint64_t>(tbb::filter_mode::serial_in_order,
                                                            [&](tbb::flow_control& fc) -> uint64_t {
                                                              if (next == n) {
                                                                fc.stop();
                                                                return 0;
                                                              }
                                                              return next++;
                                                            }) &
                               tbb::make_filter<uint64_t, uint64_t>(tbb::filter_mode::parallel,
                                                                    [&](uint64_t i) {
                                                                      compute(i);
                                                                      return i;
                                                                    }) &
                               tbb::make_filter<uint64_t, void>(tbb::filter_mode::serial_in_order,
                                                                [&](uint64_t i) { consume(i); }));
  });
}

}  // namespace

#else  // RLG_TSAN

// std::thread: t threads started for the loop and joined before it returns. Every hand-over
// goes through one mutex (the indices given out, the results ready, the first exception), so
// ThreadSanitizer sees it.

namespace {

// The state the threads of one loop share, under `mutex`.
struct Shared {
  std::mutex mutex;
  std::condition_variable changed;
  uint64_t next = 0;         // the next index to give out
  bool stop = false;         // an exception was caught: give out no more indices
  std::exception_ptr error;  // the first one

  // Records the exception being handled, if it is the first, and stops the loop.
  void Fail() {
    const std::lock_guard<std::mutex> lock(mutex);
    if (!error) error = std::current_exception();
    stop = true;
    changed.notify_all();
  }
};

// Starts `count` threads running `work`, joins them, and rethrows the loop's first exception.
template <class Work>
void RunThreads(int count, Shared& shared, Work work) {
  std::vector<std::thread> pool;
  pool.reserve(static_cast<size_t>(count));
  for (int k = 0; k < count; ++k) pool.emplace_back(work);
  for (auto& th : pool) th.join();
  if (shared.error) std::rethrow_exception(shared.error);
}

void ForOnThreads(uint64_t n, int t, const std::function<void(uint64_t)>& body) {
  Shared shared;
  RunThreads(static_cast<int>(std::min<uint64_t>(static_cast<uint64_t>(t), n)), shared, [&] {
    for (;;) {
      uint64_t i = 0;
      {
        const std::lock_guard<std::mutex> lock(shared.mutex);
        if (shared.stop || shared.next == n) return;
        i = shared.next++;
      }
      try {
        body(i);
      } catch (...) {
        shared.Fail();
        return;
      }
    }
  });
}

void PipelineOnThreads(uint64_t n, int t, const std::function<void(uint64_t)>& compute,
                       const std::function<void(uint64_t)>& consume) {
  const uint64_t tokens = PipelineTokens(t);
  Shared shared;
  uint64_t consumed = 0;                                   // indices < consumed were consumed
  std::vector<char> ready(static_cast<size_t>(tokens), 0);  // ready[i % tokens]: compute(i) returned
  // t threads compute; the first index to reach the front of the order consumes it, and every
  // ready index after it, one thread at a time (`consuming`).
  bool consuming = false;
  RunThreads(static_cast<int>(std::min<uint64_t>(static_cast<uint64_t>(t), n)), shared, [&] {
    std::unique_lock<std::mutex> lock(shared.mutex);
    for (;;) {
      // An index may start once the one `tokens` before it was consumed: its slot is free.
      shared.changed.wait(lock, [&] { return shared.stop || shared.next == n || shared.next < consumed + tokens; });
      if (shared.stop || shared.next == n) return;
      const uint64_t i = shared.next++;
      lock.unlock();
      try {
        compute(i);
      } catch (...) {
        shared.Fail();
        return;
      }
      lock.lock();
      ready[i % tokens] = 1;
      if (consuming || i != consumed) continue;  // the thread consuming, or computing consumed, takes it
      consuming = true;
      while (!shared.stop && consumed < n && ready[consumed % tokens]) {
        const uint64_t c = consumed;
        lock.unlock();
        try {
          consume(c);
        } catch (...) {
          shared.Fail();
          lock.lock();
          consuming = false;
          return;
        }
        lock.lock();
        ready[c % tokens] = 0;
        ++consumed;
        shared.changed.notify_all();
      }
      consuming = false;
    }
  });
}

}  // namespace

#endif  // RLG_TSAN

// One thread: the calls on the caller's, in index order, no pool.

void ParallelFor(uint64_t n, int threads, const std::function<void(uint64_t)>& body) {
  const int t = LoopThreads(threads);
  if (t > 1) {
    ForOnThreads(n, t, body);
    return;
  }
  for (uint64_t i = 0; i < n; ++i) body(i);
}

void detail::RunOrderedPipeline(uint64_t n, int threads, const std::function<void(uint64_t)>& compute,
                                const std::function<void(uint64_t)>& consume) {
  const int t = LoopThreads(threads);
  if (t > 1) {
    PipelineOnThreads(n, t, compute, consume);
    return;
  }
  for (uint64_t i = 0; i < n; ++i) {
    compute(i);
    consume(i);
  }
}

}  // namespace rlg::validation
