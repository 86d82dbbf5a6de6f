#!/usr/bin/env bash
# README command 2: set-up if needed, build, run the tests (about 3.5 min after the build on 2 cores).
# Left out, all run by .ci/run: label diagnosis_full (the 100-case confusion matrix, ~8 min:
#   cd build && ctest -L diagnosis_full), label memcheck (valgrind on a short simulate and
#   diagnose, ~20 s), label reference (tests/reference: the independent generator's self-tests
#   and the blind diagnoses of its data, ~9 min: cd build && ctest -L reference) and label bench
#   (every benchmark once, ~30 s: cd build && ctest -L bench).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
cd build && ctest --output-on-failure -j2 -LE 'diagnosis_full|memcheck|reference|bench' "$@"
