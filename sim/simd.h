#pragma once
/// Loops compiled twice, for AVX2 and for baseline x86-64's SSE2, with the one the machine has
/// chosen at run time (__builtin_cpu_supports and the environment variable RLG_SIMD, asked
/// once: UseAvx2). Both compile the same source with the same operations in the same order,
/// and neither fuses a multiply with an add, so both give the same bytes: twice the vector
/// width, nothing else.
/// The choice is made in code, not by the loader (target_clones): ThreadSanitizer instruments
/// the loader's resolvers, which run before it is set up, and its programs crashed at start.
/// Elsewhere than x86-64 with GCC or clang, or with RLG_NO_SIMD defined, only the baseline
/// loops are built. Every library with such loops (rlg_sim, rlg_model) is compiled with
/// -ffp-contract=off (their CMakeLists.txt), so no target fuses a multiply with an add, not even
/// a build for a machine with FMA (-march=native).
///
///   #if defined(RLG_AVX2_DISPATCH)
///   RLG_AVX2 void LoopAvx2(...) { Loop(...); }   // Loop: [[gnu::always_inline]]
///   #endif
///   void Run(...) {
///   #if defined(RLG_AVX2_DISPATCH)
///     if (rlg::sim::UseAvx2()) return LoopAvx2(...);
///   #endif
///     Loop(...);
///   }

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__)) && !defined(RLG_NO_SIMD)
#define RLG_AVX2_DISPATCH 1
#define RLG_AVX2 __attribute__((target("avx2")))

#include <cstdlib>
#include <cstring>

namespace rlg::sim {
/// Whether the AVX2 loops run: the machine has AVX2 and the environment variable RLG_SIMD is
/// not "baseline" (which runs the baseline loops on any machine, for the test that both give
/// the same bytes: tests/cli/simd_baseline.sh). Read once, at the first call; the CLI and the
/// Python module make that call at start, before any thread of theirs runs.
inline bool UseAvx2() {
  static const bool avx2 = [] {
    const char* simd = std::getenv("RLG_SIMD");
    return __builtin_cpu_supports("avx2") && !(simd && std::strcmp(simd, "baseline") == 0);
  }();
  return avx2;
}
}  // namespace rlg::sim
#endif
