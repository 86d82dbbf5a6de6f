#!/usr/bin/env bash
# stream_refuses_like_batch.sh RLGTHERM COEFFS.json: a data file with a header and no rows is
# refused by compensate in batch and in streaming mode alike: exit 2, the same message naming
# the file and line, and nothing on stdout.
set -u
bin=$1; coeffs=$2; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
printf '# a header and no data\nrun,t_s,T_amb,T1,T2,T3,T4,bias_dph\n' > "$d/empty.csv"
fail=0
(cd "$d" && "$bin" compensate empty.csv --coeffs "$coeffs" -o batch.csv > batch.out 2> batch.err); b=$?
(cd "$d" && "$bin" compensate empty.csv --coeffs "$coeffs" --stream > stream.out 2> stream.err); s=$?
(cd "$d" && "$bin" compensate - --coeffs "$coeffs" --stream < empty.csv > stdin.out 2> stdin.err); i=$?
echo "batch: exit $b: $(cat "$d/batch.err")"
echo "stream: exit $s: $(cat "$d/stream.err")"
echo "stream from stdin: exit $i: $(cat "$d/stdin.err")"
[ "$b" -eq 2 ] && [ "$s" -eq 2 ] && [ "$i" -eq 2 ] || { echo "expected exit status 2 from all three"; fail=1; }
grep -Eq "^rlgtherm: error: empty.csv:2: no data rows after the header$" "$d/batch.err" || { echo "batch message"; fail=1; }
cmp -s "$d/batch.err" "$d/stream.err" || { echo "batch and stream messages differ"; fail=1; }
grep -Eq "^rlgtherm: error: <stdin>:2: no data rows after the header$" "$d/stdin.err" || { echo "stdin message"; fail=1; }
[ ! -s "$d/stream.out" ] && [ ! -s "$d/stdin.out" ] || { echo "stream wrote to stdout"; fail=1; }
[ ! -e "$d/batch.csv" ] || { echo "batch wrote batch.csv"; fail=1; }
exit $fail
