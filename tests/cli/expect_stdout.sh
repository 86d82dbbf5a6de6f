#!/usr/bin/env bash
# expect_stdout.sh REGEX -- COMMAND...: passes when COMMAND exits 0 and its stdout matches REGEX.
set -u
regex=$1; shift 2
out=$("$@") || { echo "exit status $?"; exit 1; }
echo "$out" | head -20
echo "$out" | grep -Eq -- "$regex" || { echo "stdout does not match /$regex/"; exit 1; }
