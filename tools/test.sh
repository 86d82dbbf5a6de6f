#!/usr/bin/env bash
# README command 2: set-up if needed, build, run the tests.
# Left out, all run by .ci/run: label diagnosis_full (the 100-case confusion matrix:
#   cd build && ctest -L diagnosis_full), label memcheck (valgrind on a short simulate and
#   diagnose), label reference (tests/reference: the independent generator's self-tests and the
#   blind diagnoses of its data: cd build && ctest -L reference), label heldout (tests/heldout: a
#   second generator's cases diagnosed blind: cd build && ctest -L heldout) and label bench (every
#   benchmark once: cd build && ctest -L bench). How long each takes: docs/testing.md, "CI step times".
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
cd build && ctest --output-on-failure -j2 -LE 'diagnosis_full|memcheck|reference|heldout|bench' "$@"
