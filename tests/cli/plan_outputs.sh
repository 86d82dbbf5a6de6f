#!/usr/bin/env bash
# plan_outputs.sh RLGTHERM PLAN_DIR: `plan` gives the same bytes (JSON and text) for the same
# seed on 1, 2 and 3 threads and run twice; its JSON has the documented keys (docs/plan.md);
# no candidate meeting the target is exit 4 with "recommended": null and a reason; --verify on
# a plan with a recommendation adds "verify" with the realised p95 and exits 0.
set -eu
bin=$1; dir=$2; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
# plan exits 0 (a recommendation) or 4 (none): what is compared here is the output.
run() { "$@" || [ $? -eq 4 ]; }
for t in 1 2 3; do
  run "$bin" plan "$dir/population.toml" --threads $t --json > "$d/p$t.json"
  run "$bin" plan "$dir/population.toml" --threads $t > "$d/p$t.txt"
done
run "$bin" plan "$dir/population.toml" --threads 2 --json > "$d/again.json"
for f in json txt; do cmp "$d/p1.$f" "$d/p2.$f"; cmp "$d/p1.$f" "$d/p3.$f"; done
cmp "$d/p1.json" "$d/again.json"
status=0; "$bin" plan "$dir/impossible-target.toml" --json > "$d/none.json" || status=$?
[ "$status" -eq 4 ] || { echo "impossible target: exit $status, expected 4"; exit 1; }
"$bin" plan "$dir/verify.toml" --json --verify 64 > "$d/verify.json"
python3 - "$d/p1.json" "$d/none.json" "$d/verify.json" <<'PY'
import json, sys
p, none, v = (json.load(open(f)) for f in sys.argv[1:4])
keys = ["name", "chamber_h", "p95_abs_bias_after_dph", "p95_interval_dph", "median_abs_bias_after_dph",
        "worst_abs_bias_after_dph", "median_stability_100s_after_dph", "p95_stability_100s_after_dph", "screen",
        "meets_target", "pareto", "service", "failure"]
for c in p["candidates"]:
    missing = [k for k in keys if k not in c]
    assert not missing, (c["name"], missing)
    lo, hi = c["p95_interval_dph"]
    assert lo is None or lo <= c["p95_abs_bias_after_dph"], c["name"]
    assert "mc_to_screen_p95" in c["screen"], c["name"]
assert "recommended" in p and "reason" in p
assert none["recommended"] is None and "no candidate meets the target" in none["reason"], none["reason"]
assert v["recommended"] == "d-optimal-3", v["recommended"]
ver = v["verify"]
for k in ["realised_p95_dph", "realised_interval_dph", "consistent", "predicted_interval_dph", "gyros", "seed"]:
    assert k in ver, k
assert ver["gyros"] == 64 and ver["seed"] != v["seed"]
assert ver["consistent"] is True, ver
print(f"{len(p['candidates'])} candidates, keys present; none: {none['reason']}; verify: realised "
      f"{ver['realised_p95_dph']:.4f} {ver['realised_interval_dph']} against predicted {ver['predicted_interval_dph']}")
PY
echo "same bytes on 1, 2 and 3 threads and run twice"
