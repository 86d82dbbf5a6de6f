#!/usr/bin/env bash
# b0_column.sh RLGTHERM DATA.csv FIT_RUNS DIR: compensate's text has a "B0 err" column only for a
# model that reads a B0 window: a polynomial with a power-on offset has it, one
# with a fitted offset (no B0 at all) has not.
set -euo pipefail
bin=$1 data=$2 runs=$3 dir=$4
mkdir -p "$dir"
"$bin" fit "$data" --runs "$runs" --model poly --offset power_on -o "$dir/power_on.json" > /dev/null
"$bin" fit "$data" --runs "$runs" --model poly --offset fitted -o "$dir/fitted.json" > /dev/null
with=$("$bin" compensate "$data" --coeffs "$dir/power_on.json" | grep '^run ')
without=$("$bin" compensate "$data" --coeffs "$dir/fitted.json" | grep '^run ')
echo "power_on: $with"
echo "fitted:   $without"
[[ $with == *"B0 err"* ]] || { echo "no B0 err column for a power-on offset"; exit 1; }
[[ $without != *"B0 err"* ]] || { echo "a B0 err column for a fitted offset"; exit 1; }
