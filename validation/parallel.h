#pragma once
// The parallel loops of validation/ (population suites, plans). Two back ends, chosen when
// validation/parallel.cpp is compiled:
//  - oneTBB (the normal build): a task_arena of `threads` threads, with TBB's global cap on
//    workers lifted to `threads` (--threads N above the core count is the user's choice);
//  - std::thread, std::mutex and std::condition_variable (a RLG_TSAN build, CMake option
//    RLG_TSAN): ThreadSanitizer sees every hand-over between threads, which it cannot in
//    Debian's uninstrumented libtbb (docs/testing.md, "ThreadSanitizer").
// Both keep the same contract:
//  - threads > 0: at most that many calls of `body` / `compute` run at once, on that many
//    threads (it may exceed the core count; above n, the extra threads have nothing to do);
//    threads <= 0 means the core count. threads == 1 (or a core count of 1) runs every call on
//    the calling thread, in index order, with no pool;
//  - every index 0 <= i < n is given to `body` / `compute` exactly once; nothing else is
//    promised of the order or of which thread runs a call, so a result must not depend on it;
//  - the first exception a call throws stops the loop: no further index is handed out (TBB may
//    still finish the indices of a range one of its tasks holds), the calls under way finish,
//    then the exception propagates to the caller; a later one is lost;
//  - the caller returns only after every call has finished, and every write a call made is
//    visible to it then.
#include <cstdint>
#include <functional>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

namespace rlg::validation {

// The number of threads a loop with argument `threads` runs: threads if > 0, else the core
// count (at least 1).
int LoopThreads(int threads);

// body(i) for every 0 <= i < n, on up to `threads` threads at once.
void ParallelFor(uint64_t n, int threads, const std::function<void(uint64_t)>& body);

// The number of results an OrderedPipeline on `threads` threads holds at most: two per thread
// (LoopThreads), so that every thread stays busy while consume waits for a slow index.
uint64_t PipelineTokens(int threads);

namespace detail {
// OrderedPipeline without its result type: compute(i) stores result i in slot i % tokens,
// consume(i) takes it from there; the contract of OrderedPipeline.
void RunOrderedPipeline(uint64_t n, int threads, const std::function<void(uint64_t)>& compute,
                        const std::function<void(uint64_t)>& consume);
}  // namespace detail

// For every 0 <= i < n, consume(i, compute(i)):
//  - compute(i) -> T runs on up to `threads` threads at once (ParallelFor's contract);
//  - consume(i, T&&) runs on one thread at a time (any thread), in index order 0, 1, ..., n - 1,
//    each call after the previous one returned;
//  - at most PipelineTokens(threads) results are alive at once: compute(i) starts only after
//    consume(i - PipelineTokens(threads)) returned, so memory does not grow with n;
//  - an exception of compute or consume stops the pipeline as one of ParallelFor's does.
template <class T, class Compute, class Consume>
void OrderedPipeline(uint64_t n, int threads, Compute&& compute, Consume&& consume) {
  static_assert(std::is_convertible_v<std::invoke_result_t<Compute&, uint64_t>, T>, "compute(i) must give a T");
  // One slot per token: indices alive at once lie in a window of PipelineTokens(threads), so no
  // two of them share a slot.
  std::vector<std::optional<T>> slots(static_cast<size_t>(PipelineTokens(threads)));
  const uint64_t tokens = slots.size();
  detail::RunOrderedPipeline(
      n, threads, [&](uint64_t i) { slots[i % tokens].emplace(compute(i)); },
      [&](uint64_t i) {
        std::optional<T>& slot = slots[i % tokens];
        consume(i, std::move(*slot));
        slot.reset();
      });
}

}  // namespace rlg::validation
