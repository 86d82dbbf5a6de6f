#!/usr/bin/env bash
# diagnose_same_with_comment.sh RLGTHERM SCENARIO GYRO: diagnose on data simulated by GYRO
# itself names nothing, and an added comment line in the CSV changes no byte of the report
# (a result that moves with heap layout reads an unwritten buffer).
set -eu
bin=$1; sc=$2; gyro=$3; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
"$bin" simulate "$sc" -o "$d/a.csv" >/dev/null
{ echo "# an unrelated comment, e.g. the test bench's name"; cat "$d/a.csv"; } > "$d/b.csv"
"$bin" diagnose "$d/a.csv" --gyro "$gyro" --json > "$d/a.json"
"$bin" diagnose "$d/b.csv" --gyro "$gyro" --json > "$d/b.json"
cmp "$d/a.json" "$d/b.json"
grep -q '"cause": "none"' "$d/a.json" || { echo "the generating gyro did not explain its own data:"; grep -A3 '"cause"' "$d/a.json"; exit 1; }
echo "cause none, identical reports with and without the comment line"
