#!/usr/bin/env bash
# allan_column.sh RLGTHERM DATA.csv RUN: `allan --column my_dph` analyses that column, not
# bias_dph: a constant my_dph added to DATA reads as a constant record (nothing resolved),
# while bias_dph of the same run resolves its ARW.
set -eu
bin=$1; data=$2; run=$3; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
awk -F, '/^#/ { print; next } !h { print $0 ",my_dph"; h = 1; next } { print $0 ",0.5" }' "$data" > "$d/extra.csv"
"$bin" allan "$d/extra.csv" --run "$run" --column my_dph --json > "$d/my.json"
"$bin" allan "$d/extra.csv" --run "$run" --json > "$d/bias.json"
grep -q '"column": "my_dph"' "$d/my.json" || { echo "no column key"; exit 1; }
grep -q 'the record is constant' "$d/my.json" || { echo "my_dph was not the column analysed"; head -30 "$d/my.json"; exit 1; }
if grep -q 'the record is constant' "$d/bias.json"; then echo "bias_dph read as constant"; exit 1; fi
grep -Eq '"arw_deg_per_sqrt_h": [0-9]' "$d/bias.json" || { echo "bias_dph: ARW not resolved"; exit 1; }
echo "allan --column my_dph analysed my_dph (constant), bias_dph resolves ARW"
