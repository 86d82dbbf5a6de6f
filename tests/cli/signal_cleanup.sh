#!/usr/bin/env bash
# signal_cleanup.sh SIGNAL -- COMMAND...
# Starts COMMAND in a new, empty directory (name its outputs relative to it), waits until it
# has created something there (its temporary output), sends SIGNAL and passes when COMMAND was
# killed by that signal (exit status 128 + its number) and left nothing in the directory.
set -u
sig=$1; shift
[ "$1" = "--" ] && shift
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
# Job control on: without it a non-interactive shell starts background jobs with SIGINT
# ignored, and the signal would never reach COMMAND.
set -m
(cd "$dir" && exec "$@") >/dev/null &
pid=$!
# Poll every 10 ms for at most 60 s: the commands used here compute for about a second before
# they write, and a loaded CI machine may take many times longer.
for _ in $(seq 6000); do
  [ -n "$(ls -A "$dir")" ] && break
  kill -0 "$pid" 2>/dev/null || break
  sleep 0.01
done
seen=$(ls -A "$dir")
kill -"$sig" "$pid" 2>/dev/null
wait "$pid"
got=$?
want=$((128 + $(kill -l "$sig")))
fail=0
[ -n "$seen" ] || { echo "nothing appeared in the directory before the command ended"; fail=1; }
echo "present when $sig was sent: $seen"
if [ "$got" -ne "$want" ]; then
  echo "exit status $got, expected $want (killed by $sig)"
  [ "$got" -eq 0 ] && echo "the command finished before the signal: give it more to write"
  fail=1
fi
left=$(cd "$dir" && find . -mindepth 1 | sort)
if [ -n "$left" ]; then echo "left behind:"; echo "$left"; fail=1; fi
exit $fail
