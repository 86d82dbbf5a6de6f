#!/usr/bin/env bash
# table2_layout.sh RLGTHERM SUITE: validate's Table 2 keeps its columns aligned whatever the run
# ids' length (every row's "|" separators at the header's columns, each row as long as the
# header) and prints no "paper" columns for a suite without paper values.
set -u
out=$("$1" validate "$2" 2>/dev/null)
table=$(echo "$out" | sed -n '/^Table 2 analogue/,/^  peak100:/p' | sed '1d;$d')
echo "$table"
fail=0
header=$(echo "$table" | head -1)
bars() { echo "$1" | awk '{ s = ""; for (i = 1; i <= length($0); i++) if (substr($0, i, 1) == "|") s = s " " i; print s }'; }
want=$(bars "$header")
[ -n "$want" ] || { echo "no column separators in the header"; fail=1; }
while IFS= read -r row; do
  [ "$(bars "$row")" = "$want" ] || { echo "separators of '$row' at$(bars "$row"), the header's at$want"; fail=1; }
  [ "${#row}" -eq "${#header}" ] || { echo "row of ${#row} characters, header of ${#header}: '$row'"; fail=1; }
done < <(echo "$table" | tail -n +2)
if echo "$header" | grep -q paper; then echo "'paper' columns without paper values"; fail=1; fi
exit $fail
