#!/usr/bin/env bash
# evaluate_equals_compensate.sh RLGTHERM DATA.csv COEFFS.json: `evaluate` on the file
# `compensate -o` writes, its compensated column named, reports what `compensate` reported: the
# same JSON bytes, and the same text table below the title line. One code path, and the column
# is scored as written (1e-6 °/h), so no tolerance is needed. The runs outside the fit's ambient
# range are left out: `evaluate` knows no fitted range, so its outside_fitted_range is false.
set -eu
bin=$1; data=$2; coeffs=$3; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
"$bin" compensate "$data" --coeffs "$coeffs" --json > /dev/null 2> "$d/warnings"
awk -F, '/^#/ || NR == 1 || $1 != "fixed+60" { print }' "$data" > "$d/in_range.csv"
"$bin" compensate "$d/in_range.csv" --coeffs "$coeffs" -o "$d/out.csv" > "$d/a.txt" 2> "$d/warnings"
[ ! -s "$d/warnings" ] || { echo "runs left outside the fitted range:"; cat "$d/warnings"; exit 1; }
"$bin" compensate "$d/in_range.csv" --coeffs "$coeffs" --json > "$d/a.json"
"$bin" evaluate "$d/out.csv" --compensated bias_comp_dph --json > "$d/b.json"
grep -q '"compensated_column": "bias_comp_dph"' "$d/b.json" || { echo "no compensated_column key"; exit 1; }
cmp "$d/a.json" "$d/b.json" || { diff "$d/a.json" "$d/b.json" | head -20; exit 1; }
"$bin" evaluate "$d/out.csv" --compensated bias_comp_dph > "$d/b.txt"
head -n 1 "$d/b.txt" | grep -q "^Evaluation of bias_comp_dph against bias_dph (trend against T1)" ||
  { echo "title: $(head -n 1 "$d/b.txt")"; exit 1; }
cmp <(tail -n +2 "$d/a.txt") <(tail -n +2 "$d/b.txt") || { diff "$d/a.txt" "$d/b.txt" | head -20; exit 1; }
# A different compensated column gives different numbers (the comparison above can fail).
"$bin" evaluate "$d/out.csv" --compensated T1 --json > "$d/c.json" 2>/dev/null && cmp -s "$d/a.json" "$d/c.json" &&
  { echo "evaluate --compensated T1 gave the same JSON"; exit 1; }
echo "evaluate on compensate -o's file = compensate: JSON and table identical ($(grep -c '"run"' "$d/b.json") runs)"
