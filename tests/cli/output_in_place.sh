#!/usr/bin/env bash
# output_in_place.sh RLGTHERM SCENARIO: an output that is not a regular file is written in
# place, not replaced by a renamed temporary: a named pipe (a reader gets the data and the
# pipe stays a pipe), a descriptor name (/dev/fd/3) and, as root, a character device (a twin
# of /dev/null made with mknod in a scratch directory: the real one is never touched).
set -u
bin=$1; sc=$2; d=$(mktemp -d)
trap 'kill "$reader" 2>/dev/null; rm -rf "$d"' EXIT
reader=""
"$bin" simulate "$sc" -o - > "$d/expected.csv" || { echo "simulate -o - failed"; exit 1; }
fail=0
mkfifo "$d/pipe"
# The reader waits for a writer; 30 s bounds the wait (simulate of this scenario takes well
# under a second) when the pipe is replaced instead and no writer ever comes.
timeout 30 cat "$d/pipe" > "$d/from_pipe.csv" &
reader=$!
"$bin" simulate "$sc" -o "$d/pipe" > /dev/null; rc=$?
[ -p "$d/pipe" ] || { echo "the named pipe was replaced by a regular file"; kill "$reader" 2>/dev/null; fail=1; }
wait "$reader"
[ "$rc" -eq 0 ] || { echo "-o pipe: exit status $rc"; fail=1; }
cmp -s "$d/expected.csv" "$d/from_pipe.csv" || { echo "the pipe's reader got other bytes than -o -"; fail=1; }
"$bin" simulate "$sc" -o /dev/fd/3 3> "$d/from_fd3.csv" > /dev/null; rc=$?
[ "$rc" -eq 0 ] || { echo "-o /dev/fd/3: exit status $rc"; fail=1; }
cmp -s "$d/expected.csv" "$d/from_fd3.csv" || { echo "/dev/fd/3 got other bytes than -o -"; fail=1; }
if [ "$(id -u)" -eq 0 ]; then
  mknod "$d/null" c 1 3
  "$bin" simulate "$sc" -o "$d/null" > /dev/null; rc=$?
  [ "$rc" -eq 0 ] || { echo "-o device: exit status $rc"; fail=1; }
  [ -c "$d/null" ] || { echo "the character device was replaced by a regular file"; fail=1; }
fi
[ -z "$(ls -A "$d" | grep -v -e '^expected.csv$' -e '^from_' -e '^pipe$' -e '^null$')" ] || { echo "left: $(ls -A "$d")"; fail=1; }
[ "$fail" -eq 0 ] && echo "pipe, /dev/fd/3$([ "$(id -u)" -eq 0 ] && echo ' and a device') written in place"
exit $fail
