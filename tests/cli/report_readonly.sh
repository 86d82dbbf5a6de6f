#!/usr/bin/env bash
# report_readonly.sh REGEX_EXISTING REGEX_NEW -- COMMAND...
# COMMAND (a diagnose without --report) is run twice with a report directory it may not write:
# --report RO (an existing read-only directory) and --report RO/new (under it). Each run must
# exit 2 with stderr matching its REGEX and leave RO empty. As root (who may write anywhere)
# the commands run as user nobody through setpriv; without setpriv the test is skipped.
set -u
rx_existing=$1; rx_new=$2; shift 2
[ "$1" = "--" ] && shift
base=$(mktemp -d)
trap 'chmod -R u+w "$base"; rm -rf "$base"' EXIT
chmod 755 "$base"
ro="$base/ro"
mkdir "$ro"
chmod 555 "$ro"
as=()
if [ "$(id -u)" -eq 0 ]; then
  command -v setpriv >/dev/null || { echo "skipped: root without setpriv"; exit 77; }
  as=(setpriv --reuid=65534 --regid=65534 --clear-groups)
fi
fail=0
check() {
  local report=$1 regex=$2 err got
  err=$("${as[@]}" "${cmd[@]}" --report "$report" 2>&1 >/dev/null)
  got=$?
  echo "--- --report $report: exit $got: $err"
  [ "$got" -eq 2 ] || { echo "exit status $got, expected 2"; fail=1; }
  echo "$err" | grep -Eq -- "$regex" || { echo "stderr does not match /$regex/"; fail=1; }
  [ -z "$(ls -A "$ro")" ] || { echo "left in $ro: $(ls -A "$ro")"; fail=1; }
}
cmd=("$@")
check "$ro" "$rx_existing"
check "$ro/new" "$rx_new"
exit $fail
