#!/usr/bin/env bash
# population_threads.sh RLGTHERM SUITE: a population suite's JSON, text, JUnit and per-gyro CSV
# are the same bytes on 1, 2 and 3 threads; gyro I run alone (--gyro I) has the Table 2 numbers
# of its row in the CSV.
set -eu
bin=$1; suite=$2; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
# validate exits 0 or 4 (checks passed or failed); what is compared here is the output.
run() { "$@" || [ $? -eq 4 ]; }
for t in 1 2 3; do
  run "$bin" validate "$suite" --threads $t --json --gyros "$d/g$t.csv" --junit "$d/j$t.xml" > "$d/s$t.json"
  run "$bin" validate "$suite" --threads $t > "$d/s$t.txt"
done
for f in g.csv j.xml s.json s.txt; do
  cmp "$d/${f/./1.}" "$d/${f/./2.}"
  cmp "$d/${f/./1.}" "$d/${f/./3.}"
done
run "$bin" validate "$suite" --gyro 7 --json > "$d/g7.json"
python3 - "$d/g1.csv" "$d/g7.json" <<'PY'
import csv, json, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert [int(r["gyro"]) for r in rows] == list(range(len(rows))), "rows not in gyro order"
row = rows[7]
alone = json.load(open(sys.argv[2]))
n = 0
for e in alone["table2"]:
    # The CSV holds the shortest decimal of each double: equal as numbers, exactly.
    assert float(row[e["run"] + ".abs_bias_after_dph"]) == abs(e["bias_after_dph"]), e["run"]
    assert float(row[e["run"] + ".stability_100s_after_dph"]) == e["stability_100s_after_dph"], e["run"]
    n += 1
assert n == 4, n
print(f"gyro 7 alone = its row ({n} runs); {len(rows)} rows in order")
PY
echo "same bytes on 1, 2 and 3 threads ($(wc -l < "$d/g1.csv") CSV lines)"
