#!/usr/bin/env bash
# The ThreadSanitizer job of .ci/run: build-tsan/, clang-14 with -fsanitize=thread (CMake option
# RLG_TSAN), only the GoogleTest executables of the threaded code (target tsan_job: those
# tests/*/CMakeLists.txt mark THREADS), then `ctest -L tsan` on them (every case, or those
# matching THREADS' patterns); a race fails its test.
# RLG_TSAN_ONLY=build stops after the build, =tests runs the tests alone after it (.ci/run
# times them as steps of their own). Extra arguments go to ctest. ccache, when installed, keeps
# the objects for the next run (CMakeLists.txt).
set -euo pipefail
only=${RLG_TSAN_ONLY:-}
if [[ -n "$only" && "$only" != build && "$only" != tests ]]; then
  echo "tools/tsan.sh: RLG_TSAN_ONLY is '$only'; expected build or tests" >&2
  exit 2
fi
cd "$(dirname "$0")/.."
bash tools/setup.sh
if [[ "$only" != tests ]]; then
  CC=clang-14 CXX=clang++-14 cmake -S . -B build-tsan -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRLG_TSAN=ON >/dev/null
  cmake --build build-tsan -j"${RLG_TSAN_BUILD_JOBS:-2}" --target tsan_job >/dev/null
fi
[[ "$only" != build ]] || exit 0
cd build-tsan
ctest --output-on-failure -j"${RLG_TSAN_JOBS:-2}" -L tsan "$@"
