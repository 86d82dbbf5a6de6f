#!/usr/bin/env bash
# record_diagnoses.sh OUT_DIR: the `diagnose --json` answers on the data the diagnosis is
# proven on, for comparing a refactor's before and after (`diff -r BEFORE AFTER`):
#   - the 11 blind catalog cases of tests/diagnosis/test_diagnose.cpp (tests/diagnosis/dump_hidden_cases),
#     against the tests' nominal (scenarios/gyros/default.toml, calibration 0.5 %);
#   - scenarios/diagnosis-suite.toml as simulated (no effect), same nominal;
#   - scenarios/example-hidden-rate.toml (the README's worked example) against default.toml;
#   - the four TCLab runs against scenarios/gyros/tclab-nominal.toml with --per-run-gains.
# Needs a built tree (build/); ~2 min on one core.
set -euo pipefail
cd "$(dirname "$0")/../.."
out=$1
bin=build/bin
mkdir -p "$out/data"
"$bin/dump_hidden_cases" "$out/data"
sed 's/^relative_uncertainty = 0.05 /relative_uncertainty = 0.005/' scenarios/gyros/default.toml > "$out/data/nominal.toml"
grep -q '^relative_uncertainty = 0.005' "$out/data/nominal.toml"
for f in "$out"/data/catalog-*.csv; do
  name=$(basename "$f" .csv)
  "$bin/rlgtherm" diagnose "$f" --gyro "$out/data/nominal.toml" --json > "$out/$name.json"
done
"$bin/rlgtherm" simulate scenarios/diagnosis-suite.toml -o "$out/data/suite.csv" > /dev/null
"$bin/rlgtherm" diagnose "$out/data/suite.csv" --gyro "$out/data/nominal.toml" --json > "$out/diagnosis-suite.json"
"$bin/rlgtherm" simulate scenarios/example-hidden-rate.toml -o "$out/data/example.csv" > /dev/null
"$bin/rlgtherm" diagnose "$out/data/example.csv" --gyro scenarios/gyros/default.toml --json > "$out/example-hidden-rate.json"
tclab=data/tclab
"$bin/rlgtherm" import tclab "$tclab"/mimo*.txt -o "$out/data/tclab.csv" > /dev/null
"$bin/rlgtherm" diagnose "$out/data/tclab.csv" --gyro scenarios/gyros/tclab-nominal.toml --per-run-gains --json > "$out/tclab.json"
rm -rf "$out/data"
echo "recorded in $out"
