#!/usr/bin/env bash
# expect_status_stdout.sh STATUS REGEX -- COMMAND...: passes when COMMAND exits with STATUS and
# its stdout matches REGEX (grep -E). For `validate`, whose failed checks exit 4 with a report.
set -u
want=$1; regex=$2; shift 3
out=$("$@")
got=$?
echo "$out" | grep -E -- "FAIL|checks,|$regex" | head -20
fail=0
if [ "$got" -ne "$want" ]; then echo "exit status $got, expected $want"; fail=1; fi
if ! echo "$out" | grep -Eq -- "$regex"; then echo "stdout does not match /$regex/"; fail=1; fi
exit $fail
