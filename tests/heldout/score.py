#!/usr/bin/python3
"""Runs `rlgtherm diagnose` blind on gen.py's cases and scores it against their truth.

  /usr/bin/python3 tests/heldout/gen.py --out DIR --jobs 2 [--sample-period 60]
  /usr/bin/python3 tests/heldout/score.py --rlgtherm build/bin/rlgtherm --cases DIR --jobs 2 [--check]

Each case's report is written to DIR/CASE/diagnose.json (and power.json, below); --reuse reads
the reports already there instead (after a rebuild or a new generation, leave it out). Per
effect case, what the first accepted step says:
  named     its cause and target are the truth's;
  twin      the truth is among its ambiguous ties (the JSON's ties, ambiguous true, plausible),
            and the power analysis (`diagnose --power`) on the same data without the effect
            (data_without_effect.csv: the same gyro, schedule and noise) says the truth's target
            is never named apart from its rivals (an exact twin: `named` null) or only at a size
            above the truth's: at this size no test could name it, and the step reports the set
            it is in;
  miss      anything else, with the power analysis's sizes beside it (the truth's detected and
            named sizes: a miss below the detected size is the data's).
The power analysis is asked of data without the effect because with it, the effect's residual
inflates the noise the analysis whitens by, and so the sizes it gives.
A null case is a false alarm when any step is accepted. `--check` exits 1 unless named plus
twin reach --min-named of the effect cases (22 of 24 by default) and no null raises
an alarm. Nothing here is tuned: the diagnosis reads data.csv and nominal.toml only.
"""

import argparse
import concurrent.futures
import json
import os
import subprocess
import sys
import tomllib

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "reference"))
from survey import main_value, same_target  # noqa: E402  (the compared parameter per cause; targets)


def diagnose(rlg, case_dir, power, reuse):
    out = os.path.join(case_dir, "power.json" if power else "diagnose.json")
    if not (reuse and os.path.exists(out)):
        data = "data_without_effect.csv" if power else "data.csv"
        cmd = [rlg, "diagnose", os.path.join(case_dir, data), "--gyro",
               os.path.join(case_dir, "nominal.toml"), "--json"] + (["--power"] if power else [])
        run = subprocess.run(cmd, capture_output=True, text=True)
        if run.returncode != 0:
            raise RuntimeError("%s: exit %d: %s" % (" ".join(cmd), run.returncode, run.stderr[-400:]))
        with open(out + ".part", "w") as f:
            f.write(run.stdout)
        os.replace(out + ".part", out)
    with open(out) as f:
        return json.load(f)


def judge(truth, report, power_of, channel_node):
    """(verdict, the accepted steps as text, remark) of one case."""
    accepted = report.get("accepted", [])
    first = accepted[0] if accepted else None
    said = "; ".join("%s %s" % (a["cause"], a["target"]) for a in accepted) or "none"
    if not truth["effects"]:
        return ("false alarm" if accepted else "quiet"), said, ""
    e = truth["effects"][0]
    want = main_value(e["name"], e["parameters"])
    if first and first["cause"] == e["name"] and same_target(e["name"], first["target"], e["target"], channel_node):
        got = main_value(first["cause"], first["parameters"])
        return "named", said, "size %.2f of the truth's" % (got / want)
    ties = [t for t in (first or {}).get("ties", []) if t["ambiguous"] and t["plausible"]]
    in_ties = any(t["cause"] == e["name"] and same_target(e["name"], t["target"], e["target"], channel_node)
                  for t in ties)
    power = power_of()
    sizes = [c for c in power["power"]["candidates"]
             if c["cause"] == e["name"] and same_target(e["name"], c["target"], e["target"], channel_node)]
    if not sizes:
        return "miss", said, "the truth is not among the power analysis's candidates"
    c = sizes[0]
    def size(x):
        return "never" if x is None else "%.3g" % x
    remark = "truth %.3g; --power: detected from %s, named from %s" % (abs(want), size(c["detected"]), size(c["named"]))
    if in_ties and (c["named"] is None or c["named"] > abs(want)):
        rival = c.get("rival") or {}
        return "twin", said, remark + " (its nearest rival %s %s, cosine %.4f)" % (
            rival.get("cause"), rival.get("target"), c.get("rival_cosine") or float("nan"))
    return "miss", said, remark + (" (among the ties)" if in_ties else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rlgtherm", required=True)
    ap.add_argument("--cases", required=True, help="gen.py's output directory")
    ap.add_argument("--jobs", type=int, default=1, help="diagnoses at once")
    ap.add_argument("--reuse", action="store_true", help="read the reports already in the case directories")
    ap.add_argument("--check", action="store_true", help="exit 1 below the bar")
    ap.add_argument("--min-named", type=float, default=22 / 24, help="share of effect cases named or twins")
    a = ap.parse_args()
    rlg = os.path.abspath(a.rlgtherm)
    names = sorted(n for n in os.listdir(a.cases) if os.path.isfile(os.path.join(a.cases, n, "truth.json")))
    if not names:
        sys.exit("%s: no case directories (gen.py --out %s first)" % (a.cases, a.cases))
    dirs = [os.path.join(a.cases, n) for n in names]
    with concurrent.futures.ThreadPoolExecutor(max(1, a.jobs)) as pool:
        reports = list(pool.map(lambda d: diagnose(rlg, d, False, a.reuse), dirs))
        rows = []
        for d, report in zip(dirs, reports):
            with open(os.path.join(d, "truth.json")) as f:
                truth = json.load(f)
            with open(os.path.join(d, "nominal.toml"), "rb") as f:
                channel_node = {ch: s["node"] for ch, s in tomllib.load(f)["sensors"].items()}
            rows.append((os.path.basename(d), truth, report, channel_node, d))
        # The power analysis only where the first step is not the truth (one more diagnosis each).
        verdicts = list(pool.map(
            lambda r: judge(r[1], r[2], lambda: diagnose(rlg, r[4], True, a.reuse), r[3]), rows))
    print("| case | truth | accepted | verdict (of the first) | |")
    print("|---|---|---|---|---|")
    count = {}
    for (name, truth, _, _, _), (verdict, said, remark) in zip(rows, verdicts):
        e = truth["effects"][0] if truth["effects"] else None
        print("| %s | %s | %s | %s | %s |" % (name, "none" if e is None else "%s %s" % (e["name"], e["target"]),
                                          said, verdict, remark))
        count[verdict] = count.get(verdict, 0) + 1
    effects = sum(count.get(v, 0) for v in ("named", "twin", "miss"))
    nulls = count.get("quiet", 0) + count.get("false alarm", 0)
    named, twins, alarms = count.get("named", 0), count.get("twin", 0), count.get("false alarm", 0)
    print("\nnamed %d of %d effect cases, %d more twins at their size (the truth in the reported set); "
          "false alarms %d of %d nulls" % (named, effects, twins, alarms, nulls))
    if a.check:
        ok = named + twins >= a.min_named * effects - 1e-9 and alarms == 0
        print("check: %s (named or twins %d of %d, at least %.0f asked; false alarms %d, 0 asked)"
              % ("passed" if ok else "FAILED", named + twins, effects, a.min_named * effects, alarms))
        sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
