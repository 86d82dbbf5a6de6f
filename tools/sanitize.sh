#!/usr/bin/env bash
# The sanitizer job of .ci/run (issue #10, "Checks that stay").
#  1. build-san/: clang with AddressSanitizer + UndefinedBehaviorSanitizer (a finding aborts;
#     CMake option RLG_SANITIZE): only the CLI and the unit tests (target sanitize_job);
#  2. ctest -L sanitize: every unit test and CLI test (short diagnoses included) under them;
#     LeakSanitizer is on; PLplot's libraries' leaks are suppressed by name (tools/sanitize/lsan.supp).
# Extra arguments go to ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
if [ ! -f build-san/CMakeCache.txt ]; then
  CC=clang-14 CXX=clang++-14 cmake -S . -B build-san -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRLG_SANITIZE=ON >/dev/null
fi
cmake --build build-san -j2 --target sanitize_job >/dev/null
cd build-san
ctest --output-on-failure -j2 -L sanitize "$@"
