#!/usr/bin/env bash
# no_spec_citations.sh RLGTHERM DATA_DIR: what users read must not send them to SPEC.md, which
# they do not have: every --help text, and messages that point to a format description.
set -u
bin=$1; data=$2; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
{
  "$bin" --help
  for verb in simulate fit compare pairs compensate allan validate diagnose import; do "$bin" "$verb" --help; done
  "$bin" fit "$d/missing.csv"
  printf 'gyro = "%s"\n[[effects]]\nname = "thermal.nonsense"\ntarget = "T1"\n[[runs]]\nid = "x"\nambient = { profile = "constant", value_C = 1 }\n' \
    "$data/../../../scenarios/gyros/default.toml" > "$d/effect.toml"
  "$bin" simulate "$d/effect.toml" -o "$d/out.csv"
} > "$d/all.txt" 2>&1
if grep -n "SPEC" "$d/all.txt"; then echo "user-facing text cites SPEC (above)"; exit 1; fi
grep -q "docs/data-format.md" "$d/all.txt" || { echo "no pointer to docs/data-format.md"; exit 1; }
grep -q "the catalog (scenarios/README.md, Effects)" "$d/all.txt" || { echo "unknown effect message"; cat "$d/all.txt"; exit 1; }
echo "no SPEC citations in $(wc -l < "$d/all.txt") lines of help and messages"
