#!/usr/bin/env bash
# README command 1: set-up if needed, build, then the main job on the bundled scenarios:
# the seed paper's method end to end (simulate -> fit -> compensate -> checks), printing the
# Table 1 and Table 2 analogues and the Allan read-offs next to the paper's numbers; the same
# protocol on a population of 1,000 gyros; then the diagnosis of the measured TCLab runs
# (data/tclab) against their nominal model.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/build.sh
out=build/out
mkdir -p "$out"
build/bin/rlgtherm simulate scenarios/paper-fixed.toml -o "$out/paper-fixed.csv" >/dev/null
build/bin/rlgtherm simulate scenarios/ramps.toml -o "$out/ramps.csv" >/dev/null
echo "== rlgtherm validate scenarios/paper-suite.toml"
build/bin/rlgtherm validate scenarios/paper-suite.toml
echo
echo "Paper (Guo, Xu & Zhao 2006): at 0 °C T1 rose 1.5 °C and T2 2.5 °C; bias after compensation below"
echo "0.01 °/h; M1 (P1,P2) best. Simulated traces for your own use: $out/paper-fixed.csv, $out/ramps.csv"
echo
echo "== rlgtherm validate scenarios/paper-population.toml (1,000 gyros; per-gyro rows in $out/gyros.csv)"
# Exit status 4: a check failed on more gyros than the suite allows (docs/results.md, "Populations":
# the +60 °C hold-out); anything else is an error.
status=0
build/bin/rlgtherm validate scenarios/paper-population.toml --gyros "$out/gyros.csv" || status=$?
[ "$status" -eq 0 ] || [ "$status" -eq 4 ] || exit "$status"
if [ "$status" -eq 4 ]; then
  echo "(FAILED is the expected answer here: the held-out +60 °C run lies 10 °C beyond the calibration"
  echo " range, and more gyros than max_failing_fraction's 5 % miss its bias and 100 s stability checks;"
  echo " docs/results.md, \"Populations\". Exit status 4 means a check failed; the main job goes on.)"
fi
echo
echo "== rlgtherm diagnose: four measured TCLab runs (data/tclab) against scenarios/gyros/tclab-nominal.toml"
build/bin/rlgtherm import tclab data/tclab/mimo*.txt -o "$out/tclab.csv" >/dev/null
build/bin/rlgtherm diagnose "$out/tclab.csv" --gyro scenarios/gyros/tclab-nominal.toml --per-run-gains \
  --report "$out/tclab-diagnosis"
