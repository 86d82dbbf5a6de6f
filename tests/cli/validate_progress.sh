#!/usr/bin/env bash
# validate_progress.sh RLGTHERM SUITE UNIT COUNT: with stderr not a terminal (a CI log), validate
# prints one progress line each time another 10 % of its COUNT UNIT is done, ten lines for 10 %
# ... 100 %, each with the time elapsed and the time left; stdout is the report alone, the same
# bytes as with stderr discarded.
set -u
rlg=$1; suite=$2; unit=$3; count=$4
err=$(mktemp); out=$(mktemp)
"$rlg" validate "$suite" > "$out" 2> "$err"
fail=0
lines=$(grep -c "^rlgtherm: validate: [0-9]\+ % ([0-9]\+ of $count $unit: .*), [0-9.]\+ \(s\|min [0-9]\+ s\) elapsed, about [0-9.]\+ \(s\|min [0-9]\+ s\) left$" "$err")
[ "$lines" -eq 10 ] || { echo "$lines progress lines, expected 10"; fail=1; }
percents=$(sed -n 's/^rlgtherm: validate: \([0-9]*\) %.*/\1/p' "$err" | tr '\n' ' ')
prev=0
for p in $percents; do
  [ $((p / 10)) -gt $((prev / 10)) ] || { echo "progress $p % after $prev %: not one line per 10 %"; fail=1; }
  prev=$p
done
[ "$prev" -eq 100 ] || { echo "the last line says $prev %, not 100 %"; fail=1; }
"$rlg" validate "$suite" 2>/dev/null | cmp -s - "$out" || { echo "stdout differs with the progress on"; fail=1; }
cat "$err"; rm -f "$err" "$out"
exit $fail
