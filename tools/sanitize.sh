#!/usr/bin/env bash
# The sanitizer and fuzzing job of .ci/run.
#  1. build-san/: clang with AddressSanitizer + UndefinedBehaviorSanitizer (a finding aborts)
#     and the libFuzzer harnesses (CMake options RLG_SANITIZE, RLG_FUZZ): only the CLI, the
#     unit tests and the fuzzers (target sanitize_job), not the blind-diagnosis suites;
#  2. ctest -L sanitize -LE no_sanitize: every unit test and CLI test (short diagnoses included)
#     under them but those labelled no_sanitize where they are defined (tests/CMakeLists.txt
#     says which kind); LeakSanitizer is on; PLplot's libraries' leaks are suppressed by name (tools/sanitize/lsan.supp).
#  3. ctest -L fuzz: each harness for RLG_FUZZ_SECONDS (30) from its seed corpus, fixed seed.
# Extra arguments go to both ctest runs. RLG_SANITIZE_ONLY=build, =units or =fuzz stops after step 1,
# or runs step 2 or step 3 alone after it (.ci/run schedules them as steps of their own),
# RLG_SANITIZE_JOBS sets ctest's parallelism (2), RLG_SANITIZE_BUILD_JOBS the build's (2). ccache,
# when installed, keeps the objects for the next run (CMakeLists.txt).
set -euo pipefail
only=${RLG_SANITIZE_ONLY:-}
jobs=${RLG_SANITIZE_JOBS:-2}
if [[ -n "$only" && "$only" != build && "$only" != units && "$only" != fuzz ]]; then
  echo "tools/sanitize.sh: RLG_SANITIZE_ONLY is '$only'; expected build, units or fuzz" >&2
  exit 2
fi
cd "$(dirname "$0")/.."
bash tools/setup.sh
# CC and CXX count on the first configure; the options every time (a build-san made without
# them gets them).
CC=clang-14 CXX=clang++-14 cmake -S . -B build-san -DCMAKE_BUILD_TYPE=RelWithDebInfo -DRLG_FUZZ=ON >/dev/null
cmake --build build-san -j"${RLG_SANITIZE_BUILD_JOBS:-2}" --target sanitize_job >/dev/null
[[ "$only" != build ]] || exit 0
cd build-san
[[ "$only" == fuzz ]] || ctest --output-on-failure -j"$jobs" -L sanitize -LE no_sanitize "$@"
[[ "$only" == units ]] || ctest --output-on-failure -j"$jobs" -L fuzz "$@"
