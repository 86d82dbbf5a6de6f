#!/usr/bin/env bash
# README command 2: set-up if needed, build, run the tests (~1.5 min after the build).
# Left out: label diagnosis_full (the 100-case confusion matrix, ~6 min; .ci/run runs it):
#   cd build && ctest -L diagnosis_full
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
cd build && ctest --output-on-failure -j2 -LE diagnosis_full "$@"
