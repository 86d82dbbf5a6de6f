// The parallel loops of validation/parallel.h, on the back end the build has (oneTBB; std::thread
// in the ThreadSanitizer build, which runs these tests too): every index once, consume serial
// and in index order, at most PipelineTokens(threads) results alive, at most `threads` calls at
// once, the first exception rethrown, threads == 1 on the calling thread, threads > n.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "validation/parallel.h"

namespace rlg::validation {
namespace {

// How many calls run at once, and the most there were.
struct Concurrency {
  std::atomic<int> now{0};
  std::atomic<int> peak{0};
  void Enter() {
    const int n = ++now;
    int p = peak.load();
    while (n > p && !peak.compare_exchange_weak(p, n)) {
    }
  }
  void Leave() { --now; }
};

// A result that counts the live results (constructed, not yet destroyed, not moved from).
class Live {
 public:
  Live(uint64_t index, Concurrency* live) : index_(index), live_(live) { live_->Enter(); }
  Live(Live&& o) noexcept : index_(o.index_), live_(std::exchange(o.live_, nullptr)) {}
  Live& operator=(Live&&) = delete;
  ~Live() {
    if (live_) live_->Leave();
  }
  uint64_t index() const { return index_; }

 private:
  uint64_t index_;
  Concurrency* live_;
};

void Spin(std::chrono::microseconds d) { std::this_thread::sleep_for(d); }

const int kThreads[] = {1, 2, 3, 8};

TEST(ParallelFor, GivesEveryIndexExactlyOnceOnAtMostThreadsAtOnce) {
  for (int threads : kThreads) {
    for (uint64_t n : {0u, 1u, 5u, 200u}) {  // 8 threads > n = 5
      std::vector<std::atomic<int>> hits(n);
      Concurrency running;
      ParallelFor(n, threads, [&](uint64_t i) {
        running.Enter();
        ++hits[i];
        if (i % 16 == 0) Spin(std::chrono::microseconds(200));
        running.Leave();
      });
      for (uint64_t i = 0; i < n; ++i) EXPECT_EQ(hits[i].load(), 1) << "threads " << threads << ", index " << i;
      EXPECT_LE(running.peak.load(), threads) << "n " << n;
    }
  }
}

TEST(ParallelFor, OneThreadIsTheCallersInIndexOrder) {
  const auto caller = std::this_thread::get_id();
  std::vector<uint64_t> order;
  ParallelFor(10, 1, [&](uint64_t i) {
    EXPECT_EQ(std::this_thread::get_id(), caller);
    order.push_back(i);
  });
  ASSERT_EQ(order.size(), 10u);
  for (uint64_t i = 0; i < 10; ++i) EXPECT_EQ(order[i], i);
}

TEST(ParallelFor, RethrowsTheExceptionOfACallAndFinishesTheOthers) {
  for (int threads : kThreads) {
    Concurrency running;
    std::atomic<int> calls{0};
    EXPECT_THROW(ParallelFor(100, threads,
                             [&](uint64_t i) {
                               running.Enter();
                               ++calls;
                               Spin(std::chrono::microseconds(50));
                               running.Leave();
                               if (i == 7) throw std::runtime_error("index 7");
                             }),
                 std::runtime_error)
        << "threads " << threads;
    EXPECT_EQ(running.now.load(), 0) << "a call still runs after ParallelFor returned";
    EXPECT_GE(calls.load(), 1);
  }
}

TEST(LoopThreads, IsTheArgumentOrTheCoreCount) {
  EXPECT_EQ(LoopThreads(5), 5);
  EXPECT_GE(LoopThreads(0), 1);
  EXPECT_EQ(LoopThreads(-1), LoopThreads(0));
  EXPECT_EQ(PipelineTokens(3), 6u);
}

TEST(OrderedPipeline, ConsumesEveryResultOnceInIndexOrderWithAtMostTheTokensAlive) {
  for (int threads : kThreads) {
    for (uint64_t n : {0u, 1u, 5u, 300u}) {
      Concurrency computing;
      Concurrency consuming;
      Concurrency live;
      std::vector<uint64_t> order;
      OrderedPipeline<Live>(
          n, threads,
          [&](uint64_t i) {
            computing.Enter();
            // A slow index now and then: later ones pile up behind it for the in-order consume.
            if (i % 50 == 0) Spin(std::chrono::milliseconds(5));
            Live r(i, &live);
            computing.Leave();
            return r;
          },
          [&](uint64_t i, Live&& r) {
            consuming.Enter();
            EXPECT_EQ(r.index(), i);
            order.push_back(i);
            const Live taken = std::move(r);
            consuming.Leave();
          });
      ASSERT_EQ(order.size(), n) << "threads " << threads;
      for (uint64_t i = 0; i < n; ++i) EXPECT_EQ(order[i], i) << "threads " << threads;
      EXPECT_LE(computing.peak.load(), threads);
      EXPECT_LE(consuming.peak.load(), 1);
      EXPECT_LE(static_cast<uint64_t>(live.peak.load()), PipelineTokens(threads)) << "threads " << threads;
      EXPECT_EQ(live.now.load(), 0);
    }
  }
}

TEST(OrderedPipeline, OneThreadIsTheCallersComputeThenConsumeOfEachIndex) {
  const auto caller = std::this_thread::get_id();
  std::vector<int> calls;  // +i compute, -i consume, of index i + 1
  OrderedPipeline<int>(
      3, 1,
      [&](uint64_t i) {
        EXPECT_EQ(std::this_thread::get_id(), caller);
        calls.push_back(static_cast<int>(i) + 1);
        return static_cast<int>(i);
      },
      [&](uint64_t i, int&& v) {
        EXPECT_EQ(std::this_thread::get_id(), caller);
        EXPECT_EQ(v, static_cast<int>(i));
        calls.push_back(-static_cast<int>(i) - 1);
      });
  EXPECT_EQ(calls, (std::vector<int>{1, -1, 2, -2, 3, -3}));
}

TEST(OrderedPipeline, RethrowsTheExceptionOfComputeOrConsume) {
  for (int threads : kThreads) {
    for (bool in_consume : {false, true}) {
      Concurrency live;
      std::vector<uint64_t> consumed;
      try {
        OrderedPipeline<Live>(
            100, threads,
            [&](uint64_t i) {
              if (!in_consume && i == 20) throw std::runtime_error("compute 20");
              return Live(i, &live);
            },
            [&](uint64_t i, Live&&) {
              if (in_consume && i == 20) throw std::runtime_error("consume 20");
              consumed.push_back(i);
            });
        ADD_FAILURE() << "no exception, threads " << threads;
      } catch (const std::runtime_error& e) {
        EXPECT_STREQ(e.what(), in_consume ? "consume 20" : "compute 20");
      }
      // Consumed in order up to the failure, never past it; every result destroyed.
      ASSERT_LE(consumed.size(), 20u);
      for (size_t k = 0; k < consumed.size(); ++k) EXPECT_EQ(consumed[k], k);
      EXPECT_EQ(live.now.load(), 0);
    }
  }
}

}  // namespace
}  // namespace rlg::validation
