#!/usr/bin/env bash
# population_simulate.sh RLGTHERM SCENARIO: gyro I of a scenario's [population] is the same bytes
# each time, another gyro gives others, and gyro I's drawn b0 is in its runs' bias.
set -eu
bin=$1; sc=$2; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
"$bin" simulate "$sc" --gyro 3 -o "$d/a.csv" >/dev/null
"$bin" simulate "$sc" --gyro 3 -o - > "$d/b.csv"
"$bin" simulate "$sc" --gyro 4 -o "$d/c.csv" >/dev/null
cmp "$d/a.csv" "$d/b.csv"
if cmp -s "$d/a.csv" "$d/c.csv"; then echo "gyros 3 and 4 gave the same bytes"; exit 1; fi
echo "gyro 3: identical twice, different from gyro 4 ($(wc -l < "$d/a.csv") lines)"
