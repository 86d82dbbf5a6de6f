#!/usr/bin/env bash
# plot_files.sh DIR FILE... -- COMMAND...: runs COMMAND twice, without and with `--plot DIR`,
# and passes when both exit with the same status, print the same stdout to the byte, and DIR
# then holds exactly the FILEs: each a PNG (signature \x89PNG\r\n\x1a\n, IHDR first) of
# 800..2000 x 600..2000 pixels (the figures are drawn at 1200..1400 x 800..1200) and over 10 KB
# (a frame, labels and curves; an empty page of that size is ~5 KB).
set -u
dir=$1; shift
files=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do files+=("$1"); shift; done
shift
rm -rf "$dir"
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
"$@" > "$out/without" 2> "$out/without.err"; s1=$?
"$@" --plot "$dir" > "$out/with" 2> "$out/with.err"; s2=$?
fail=0
[ "$s1" -eq "$s2" ] || { echo "exit status $s1 without --plot, $s2 with"; fail=1; }
cmp "$out/without" "$out/with" || { echo "stdout differs with --plot:"; diff "$out/without" "$out/with" | head; fail=1; }
be32() { od -An -tu1 -j "$2" -N4 "$1" | awk '{ print $1 * 16777216 + $2 * 65536 + $3 * 256 + $4 }'; }
for f in "${files[@]}"; do
  p="$dir/$f"
  [ -f "$p" ] || { echo "missing: $p"; fail=1; continue; }
  [ "$(head -c 16 "$p" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a0000000d49484452" ] || { echo "not a PNG: $p"; fail=1; continue; }
  size=$(stat -c %s "$p"); w=$(be32 "$p" 16); h=$(be32 "$p" 20)
  [ "$size" -gt 10000 ] || { echo "$p: only $size bytes"; fail=1; }
  { [ "$w" -ge 800 ] && [ "$w" -le 2000 ] && [ "$h" -ge 600 ] && [ "$h" -le 2000 ]; } || { echo "$p: $w x $h pixels"; fail=1; }
  echo "$f: $w x $h, $size bytes"
done
want=$(printf '%s\n' "${files[@]}" | sort)
got=$(cd "$dir" 2>/dev/null && find . -mindepth 1 -printf '%P\n' | sort)
[ "$want" = "$got" ] || { echo "DIR holds:"; echo "$got"; echo "expected:"; echo "$want"; fail=1; }
echo "--- stderr with --plot:"; cat "$out/with.err"
exit $fail
