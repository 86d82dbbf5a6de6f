#!/usr/bin/env bash
# report_files.sh DIR FILE... -- COMMAND...: runs COMMAND (which writes a report into DIR) and
# passes when it exits 0 and every FILE exists in DIR, non-empty; *.png files must be PNG
# (signature \x89PNG\r\n\x1a\n) and *.csv files must have a header and at least one row.
set -u
dir=$1; shift
files=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do files+=("$1"); shift; done
shift
rm -rf "$dir"
"$@" > /dev/null || { echo "exit status $?"; exit 1; }
for f in "${files[@]}"; do
  p="$dir/$f"
  [ -s "$p" ] || { echo "missing or empty: $p"; exit 1; }
  case "$f" in
    *.png) [ "$(head -c 8 "$p" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] || { echo "not a PNG: $p"; exit 1; } ;;
    *.csv) [ "$(wc -l < "$p")" -ge 2 ] || { echo "no data rows: $p"; exit 1; } ;;
  esac
done
ls "$dir"
