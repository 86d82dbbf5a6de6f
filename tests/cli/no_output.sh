#!/usr/bin/env bash
# no_output.sh [--fsize KB] [--stdout FILE] STATUS REGEX -- COMMAND...
# Runs COMMAND in a new, empty directory (name its outputs relative to it) and passes when its
# exit status is STATUS, its stderr matches REGEX (grep -E) and the directory is still empty
# afterwards: no output file, no partial or temporary one, hidden or not.
#   --fsize KB   limits the size of every file written to KB kibibytes (bash's ulimit -f) with
#                SIGXFSZ ignored, so that a write past the limit fails with EFBIG: a full disk
#                without root.
#   --stdout F   sends COMMAND's stdout to F (e.g. /dev/full) instead of /dev/null.
set -u
fsize=""; out=/dev/null
while [ $# -gt 0 ]; do
  case "$1" in
    --fsize) fsize=$2; shift 2 ;;
    --stdout) out=$2; shift 2 ;;
    *) break ;;
  esac
done
want=$1; regex=$2; shift 2
[ "$1" = "--" ] && shift
if [ "$out" != /dev/null ] && [ ! -e "$out" ]; then echo "skipped: no $out here"; exit 77; fi
dir=$(mktemp -d); err=$(mktemp)
trap 'rm -rf "$dir" "$err"' EXIT
if [ -n "$fsize" ]; then
  (cd "$dir" && trap '' XFSZ && ulimit -f "$fsize" && exec "$@") >"$out" 2>"$err"
else
  (cd "$dir" && exec "$@") >"$out" 2>"$err"
fi
got=$?
fail=0
if [ "$got" -ne "$want" ]; then echo "exit status $got, expected $want"; fail=1; fi
if ! grep -Eq -- "$regex" "$err"; then echo "stderr does not match /$regex/"; fail=1; fi
left=$(cd "$dir" && find . -mindepth 1 | sort)
if [ -n "$left" ]; then echo "output left behind:"; echo "$left"; fail=1; fi
echo "--- stderr:"; cat "$err"
exit $fail
