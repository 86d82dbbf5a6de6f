#!/usr/bin/env bash
# smoke.sh PYTHON RLGTHERM WORKDIR: rlgtherm accepts data it did not make. Generates the refgen
# cases 'none' and 'thermal.missing_link' at 10 s and runs `rlgtherm diagnose --json` on each;
# passes when every diagnose exits 0 and prints valid JSON with the report's keys (docs/data-format.md).
# What diagnose names is not checked here (tests/reference/survey.py reports that).
set -u
py=$1; rlg=$2; work=$3
here=$(cd "$(dirname "$0")" && pwd)
fail=0
for c in none thermal.missing_link; do
  d="$work/$c"
  rm -rf "$d"
  if ! "$py" "$here/refgen.py" "$c" --seed 1 --sample-period 10 --out "$d"; then
    echo "refgen failed for $c"; fail=1; continue
  fi
  "$rlg" diagnose "$d/data.csv" --gyro "$d/nominal.toml" --json >"$d/diagnose.json" 2>"$d/diagnose.err"
  st=$?
  if [ "$st" -ne 0 ]; then
    echo "$c: diagnose exit status $st, expected 0"; cat "$d/diagnose.err"; fail=1; continue
  fi
  if ! "$py" -c 'import json, sys
r = json.load(open(sys.argv[1]))
missing = [k for k in ("cause", "target", "parameters", "baseline", "extended", "gain", "candidates", "accepted") if k not in r]
sys.exit("missing keys: %s" % missing if missing else 0)' "$d/diagnose.json"; then
    echo "$c: diagnose --json is not valid JSON with the report's keys"; fail=1; continue
  fi
  echo "$c: diagnose exit 0, cause $("$py" -c 'import json,sys; r=json.load(open(sys.argv[1])); print(r["cause"], r.get("target"))' "$d/diagnose.json")"
done
exit $fail
