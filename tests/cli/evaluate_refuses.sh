#!/usr/bin/env bash
# evaluate_refuses.sh RLGTHERM DATA.csv: `evaluate` refuses a compensated column that is
# missing or holds NaN in a row, and a missing trend channel: exit 2, file:line and
# what was expected on stderr, nothing on stdout (no partial table).
set -u
bin=$1; data=$2; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
# my_dph = 0.5 everywhere, then NaN in the 5th data row (line 5 + the comment lines + header).
awk -F, '/^#/ { print; next } !h { print $0 ",my_dph"; h = 1; next } { n++; print $0 "," (n == 5 ? "nan" : "0.5") }' \
  "$data" > "$d/nan.csv"
nan_line=$(( $(grep -c '^#' "$data") + 1 + 5 ))
fail=0
check() {  # check REGEX -- COMMAND...
  local regex=$1; shift 2
  "$@" > "$d/out" 2> "$d/err"; local got=$?
  if [ "$got" -ne 2 ]; then echo "exit status $got, expected 2: $*"; fail=1; fi
  if ! grep -Eq -- "$regex" "$d/err"; then echo "stderr does not match /$regex/:"; cat "$d/err"; fail=1; fi
  if [ -s "$d/out" ]; then echo "output on stdout:"; head -3 "$d/out"; fail=1; fi
}
check "nan.csv:[0-9]+: no column 'nope' \\(the columns are: run,t_s,T_amb,T1,T2,T3,T4,bias_dph,my_dph\\)" -- \
  "$bin" evaluate "$d/nan.csv" --compensated nope --json
check "nan.csv:$nan_line: column 9 \\('my_dph'\\): expected a finite number, found 'nan'" -- \
  "$bin" evaluate "$d/nan.csv" --compensated my_dph
check "fixed.csv:[0-9]+: run 'fixed-30' has no column 'T9'" -- "$bin" evaluate "$data" --compensated bias_dph --trend-channel T9
[ $fail -eq 0 ] && echo "evaluate refused a missing column, a NaN and a missing trend channel: exit 2, nothing on stdout"
exit $fail
