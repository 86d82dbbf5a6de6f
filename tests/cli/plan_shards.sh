#!/usr/bin/env bash
# plan_shards.sh RLGTHERM PLAN: the shards of `plan --gyros FROM:TO --json`, run apart (on other
# thread counts) and merged in any order with --merge, give the bytes of the plan run in one
# piece, JSON and text; a gyro in two shards, a gyro in none, and a shard of another plan are
# refused (exit 2) naming the file.
set -u
bin=$1; plan=$2; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
fail=0
run() { "$@"; s=$?; [ $s -eq 0 ] || [ $s -eq 4 ] || { echo "exit $s: $*"; fail=1; }; }
run "$bin" plan "$plan" --json > "$d/full.json"
run "$bin" plan "$plan" > "$d/full.txt"
run "$bin" plan "$plan" --gyros 0:5 --threads 1 > "$d/a.json"
run "$bin" plan "$plan" --gyros 5:11 --threads 2 > "$d/b.json"
run "$bin" plan "$plan" --gyros 11:16 --threads 3 > "$d/c.json"
run "$bin" plan "$plan" --merge "$d/c.json" "$d/a.json" "$d/b.json" --json > "$d/merged.json"
run "$bin" plan "$plan" --merge "$d/a.json" "$d/b.json" "$d/c.json" > "$d/merged.txt"
cmp "$d/full.json" "$d/merged.json" || { echo "merged JSON differs"; fail=1; }
cmp "$d/full.txt" "$d/merged.txt" || { echo "merged text differs"; fail=1; }
expect() {  # expect REGEX ARGS..: exit 2 and stderr matching REGEX
  local regex=$1; shift
  "$bin" plan "$@" > /dev/null 2> "$d/err"; local s=$?
  [ $s -eq 2 ] && grep -Eq -- "$regex" "$d/err" || { echo "plan $*: exit $s, stderr:"; cat "$d/err"; fail=1; }
}
expect "a.json: gyro 0 is also in .*a.json" "$plan" --merge "$d/a.json" "$d/a.json" "$d/b.json" "$d/c.json"
expect "no shard holds gyro 5 " "$plan" --merge "$d/a.json" "$d/c.json"
cp "$plan" "$d/other.toml"; echo "# another plan" >> "$d/other.toml"
sed -i "s|\"../../../scenarios|\"$(cd "$(dirname "$plan")" && pwd)/../../../scenarios|" "$d/other.toml"
expect "a.json: a shard of another plan file or seed" "$d/other.toml" --merge "$d/a.json" "$d/b.json" "$d/c.json"
expect "--gyros 3:99: expected FROM < TO <= 16" "$plan" --gyros 3:99
[ $fail -eq 0 ] && echo "three shards merged = the plan in one piece (JSON and text); refusals named"
exit $fail
