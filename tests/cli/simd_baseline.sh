#!/usr/bin/env bash
# simd_baseline.sh RLGTHERM SUITE SCENARIO...: the loops compiled for AVX2 and for the baseline
# (sim/simd.h) give the same bytes. Each scenario's .npz and the population suite's per-gyro CSV
# (every metric's shortest decimal) and JSON are made twice, the second time with
# RLG_SIMD=baseline, and compared byte for byte. On a machine without AVX2 both runs would take
# the baseline loops: the test is skipped (exit 77), saying so.
set -eu
if ! grep -qw avx2 /proc/cpuinfo 2>/dev/null; then
  echo "skipped: no AVX2 here, so only the baseline loops run"
  exit 77
fi
unset RLG_SIMD  # the first pass takes the AVX2 loops whatever the caller's environment
bin=$1; suite=$2; shift 2; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
# validate exits 0 or 4 (checks passed or failed); what is compared here is the output.
run() { "$@" || [ $? -eq 4 ]; }
for mode in native baseline; do
  [ "$mode" = baseline ] && export RLG_SIMD=baseline
  n=0
  for scenario in "$@"; do
    "$bin" simulate "$scenario" -o "$d/$mode-$n.npz"
    n=$((n + 1))
  done
  run "$bin" validate "$suite" --json --gyros "$d/$mode-gyros.csv" > "$d/$mode-suite.json"
done
for f in "$d"/native-*; do cmp "$f" "${f/native-/baseline-}"; done
echo "the same bytes with and without the AVX2 loops ($# scenarios, $(wc -l < "$d/native-gyros.csv") CSV lines)"
