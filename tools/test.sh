#!/usr/bin/env bash
# README command 2: set-up if needed, build, run every test.
# -LE diagnosis_full leaves out the slow catalog-wide diagnosis test (README, "Diagnosis status");
# run it with: cd build && ctest -L diagnosis_full
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
cd build && ctest --output-on-failure -j2 -LE diagnosis_full "$@"
