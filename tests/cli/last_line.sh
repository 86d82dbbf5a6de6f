#!/usr/bin/env bash
# last_line.sh REGEX -- COMMAND...: passes when COMMAND exits 0 and the last line of its stdout
# matches REGEX (grep -E).
set -u
regex=$1; shift
[ "$1" = "--" ] && shift
out=$(mktemp); trap 'rm -f "$out"' EXIT
"$@" > "$out" || { echo "exit status $?, expected 0"; cat "$out"; exit 1; }
last=$(tail -n 1 "$out")
echo "last line: $last"
echo "$last" | grep -Eq -- "$regex" || { echo "does not match /$regex/"; exit 1; }
