#!/usr/bin/env bash
# expect.sh STATUS REGEX [--no-file PATH] -- COMMAND...
# Runs COMMAND; passes when its exit status is STATUS and its stderr matches REGEX (grep -E),
# and, with --no-file, when PATH does not exist afterwards (no partial output).
set -u
want=$1; regex=$2; shift 2
nofile=""
if [ "$1" = "--no-file" ]; then nofile=$2; shift 2; fi
[ "$1" = "--" ] && shift
[ -n "$nofile" ] && rm -f "$nofile"
err=$(mktemp)
"$@" >/dev/null 2>"$err"
got=$?
fail=0
if [ "$got" -ne "$want" ]; then echo "exit status $got, expected $want"; fail=1; fi
if ! grep -Eq -- "$regex" "$err"; then echo "stderr does not match /$regex/"; fail=1; fi
if [ -n "$nofile" ] && ls "$nofile"* >/dev/null 2>&1; then echo "partial output left: $(ls "$nofile"*)"; fail=1; fi
echo "--- stderr:"; cat "$err"; rm -f "$err"
exit $fail
