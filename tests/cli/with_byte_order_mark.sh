#!/usr/bin/env bash
# with_byte_order_mark.sh CSV COPY -- COMMAND...: writes COPY, CSV with a UTF-8 byte-order mark
# before its first byte (as a spreadsheet saves it), then runs COMMAND (which reads COPY) and
# passes its exit status on: the mark before the header is no error.
set -eu
csv=$1; copy=$2; shift 2
[ "$1" = "--" ] && shift
printf '\357\273\277' > "$copy"
cat "$csv" >> "$copy"
exec "$@"
