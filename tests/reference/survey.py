#!/usr/bin/python3
"""Runs `rlgtherm diagnose` on every refgen case and prints what it named against the truth.

  /usr/bin/python3 tests/reference/survey.py --rlgtherm build/bin/rlgtherm \
      --strength 10 --sample-period 10 --seeds 1,2 [--cases a,b] [--work DIR] [--json OUT]

Columns: case, seed, the truth (effect, target, main parameter), what diagnose accepted first
(`accepted[0]`, or none), the step at which a hidden effect's cause was accepted (* when with
another target), its main parameter over the truth's, every accepted step, the held-out ratio of
the first. `--table-only --work DIR` prints the table of an earlier or interrupted survey.
A baseline only: nothing here is tuned to make the diagnosis pass.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import refgen  # noqa: E402

# The parameter compared per cause (hysteresis: only k_heating - k_cooling is identifiable).
MAIN = {
    "thermal.missing_mass": "heat_capacity_J_per_K",
    "thermal.missing_link": "conductance_W_per_K",
    "thermal.power_drift": "g_per_C",
    "thermal.radiation": "emissivity_area_m2",
    "sensor.lag": "time_constant_s",
    "sensor.offset": "offset_C",
    "bias.temperature_rate": "k_dph_per_C_per_min",
    "bias.gradient": "k_dph_per_C",
    "bias.hysteresis": "k_heating_minus_cooling",
    "bias.mode_hop": "step_dph",
    "near.reversible_hops": "step_dph",
}


def main_value(cause, params):
    if not params:
        return None
    if cause == "bias.hysteresis":
        if "k_heating_dph_per_C" in params and "k_cooling_dph_per_C" in params:
            return params["k_heating_dph_per_C"] - params["k_cooling_dph_per_C"]
        return params.get("k_heating_minus_cooling_dph_per_C")
    return params.get(MAIN.get(cause, ""), None)


def short(cause, target, value):
    s = cause if target in (None, "") else "%s %s" % (cause, target)
    if value is not None:
        s += " (%.3g)" % value
    return s


def run_case(rlg, case, seed, period, strength, work, exact_ambient=False):
    d = os.path.join(work, "%s-s%d-p%g-x%g" % (case, seed, period, strength))
    refgen.write_case(refgen.generate(case, seed, period, strength,
                                      exact_ambient=exact_ambient), d)
    truth = json.load(open(os.path.join(d, "truth.json")))
    t0 = time.time()
    p = subprocess.run([rlg, "diagnose", os.path.join(d, "data.csv"), "--gyro",
                        os.path.join(d, "nominal.toml"), "--json"],
                       stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    dt = time.time() - t0
    row = {"case": case, "seed": seed, "period": period, "strength": strength,
           "truth": truth, "status": p.returncode, "seconds": dt}
    if p.returncode != 0:
        row["error"] = p.stderr.strip().splitlines()[-1] if p.stderr.strip() else ""
        return row
    rep = json.loads(p.stdout)
    with open(os.path.join(d, "diagnose.json"), "w") as f:
        f.write(p.stdout)
    row["accepted"] = accepted_of(rep)
    row["prior_conflicts"] = rep.get("calibration", {}).get("prior_conflicts", [])
    return row


def accepted_of(rep):
    """The report's accepted steps, with what the scoring reads: cause, target, parameters,
    held-out ratio, plausibility, kind, notes and the step's ties ({cause, target,
    score_difference, heldout_difference, ambiguous, plausible}; see docs/data-format.md)."""
    return [{"cause": a.get("cause"), "target": a.get("target"),
             "parameters": a.get("parameters", {}),
             "heldout_rms_ratio": a.get("heldout_rms_ratio"),
             "plausible": a.get("plausible"), "kind": a.get("kind"), "notes": a.get("notes") or [],
             "ties": a.get("ties") or []} for a in rep.get("accepted", [])]


def rows_from_work(work):
    """Rows of an earlier (or interrupted) survey, from its work directory."""
    rows = []
    for name in sorted(os.listdir(work)):
        d = os.path.join(work, name)
        if not os.path.exists(os.path.join(d, "diagnose.json")):
            continue
        truth = json.load(open(os.path.join(d, "truth.json")))
        rep = json.load(open(os.path.join(d, "diagnose.json")))
        rows.append({"case": truth["case"], "seed": truth["seed"], "truth": truth, "status": 0,
                     "seconds": float("nan"),
                     "accepted": accepted_of(rep)})
    order = list(refgen.CASES)
    rows.sort(key=lambda r: (order.index(r["case"]), r["seed"]))
    return rows


CHANNEL_NODE = {ch: sen["node"] for ch, sen in refgen.reference_gyro()["sensors"].items()}


def same_target(cause, got, want, channel_node=CHANNEL_NODE):
    """Targets equal up to naming: a channel means its node (channel_node: refgen's gyro unless
    given) except for sensor.* effects, and a pair may come in either order."""
    if got is None or want is None:
        return got == want
    if cause.startswith("sensor."):
        return got == want

    def norm(t):
        parts = [channel_node.get(p, p) for p in t.split("-")]
        return tuple(sorted(parts)) if len(parts) == 2 else tuple(parts)
    return norm(got) == norm(want)


def table(rows):
    """Markdown table. 'truth at step': the first accepted step whose cause is a hidden effect's
    (k, or k* when its target differs), and its main parameter over the truth's."""
    out = ["| case | seed | truth | first accepted | truth at step | param ratio | all accepted"
           " | held-out (first) |",
           "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        t = r["truth"]
        truth = short(t["effect"], t["target"], main_value(t["effect"], t["parameters"]))
        for e2 in t["effects"][1:]:
            truth += " + " + short(e2["name"], e2["target"], main_value(e2["name"], e2["parameters"]))
        if r["status"] != 0:
            out.append("| %s | %d | %s | exit %d: %s | | | | |"
                       % (r["case"], r["seed"], truth, r["status"], r.get("error", "")))
            continue
        acc = r["accepted"]
        named, held = "none", ""
        if acc:
            a = acc[0]
            named = short(a["cause"], a["target"], main_value(a["cause"], a["parameters"]))
            if a.get("plausible") is False:
                named += " [implausible]"
            held = "%.3f" % a["heldout_rms_ratio"] if a.get("heldout_rms_ratio") else ""
        found, ratio = [], []
        for e in t["effects"]:
            for k, a in enumerate(acc, start=1):
                if a["cause"] == e["name"]:
                    ok = same_target(e["name"], a["target"], e["target"])
                    found.append("%d%s" % (k, "" if ok else "*"))
                    v, av = main_value(e["name"], e["parameters"]), main_value(a["cause"], a["parameters"])
                    ratio.append("%.2f" % (av / v) if v and av is not None else "?")
                    break
            else:
                found.append("-")
                ratio.append("")
        every = "; ".join("%s %s" % (a["cause"], a["target"] or "") for a in acc) or "-"
        out.append("| %s | %d | %s | %s | %s | %s | %s | %s |"
                   % (r["case"], r["seed"], truth, named, ", ".join(found),
                      ", ".join(x for x in ratio if x), every, held))
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rlgtherm", required=True)
    ap.add_argument("--strength", type=float, default=10.0)
    ap.add_argument("--sample-period", type=float, default=10.0)
    ap.add_argument("--seeds", default="1")
    ap.add_argument("--cases", default=",".join(refgen.CASES))
    ap.add_argument("--work", default=None)
    ap.add_argument("--json", default=None, help="also write the rows as JSON")
    ap.add_argument("--exact-ambient", action="store_true", help="refgen --exact-ambient")
    ap.add_argument("--table-only", action="store_true",
                    help="print the table of the cases already diagnosed in --work, run nothing")
    a = ap.parse_args()
    if a.table_only:
        print(table(rows_from_work(a.work)))
        return 0
    work = a.work or tempfile.mkdtemp(prefix="refgen-survey-")
    rows = []
    for case in a.cases.split(","):
        for seed in [int(s) for s in a.seeds.split(",")]:
            rows.append(run_case(a.rlgtherm, case, seed, a.sample_period, a.strength, work,
                                 a.exact_ambient))
            print("%s seed %d: %s" % (case, seed, rows[-1].get("accepted", rows[-1].get("error"))),
                  file=sys.stderr, flush=True)
    print("strength %g, sample period %g s, seeds %s%s (data in %s)\n"
          % (a.strength, a.sample_period, a.seeds,
             ", exact ambient" if a.exact_ambient else "", work))
    print(table(rows))
    if a.json:
        with open(a.json, "w") as f:
            json.dump([{k: v for k, v in r.items() if k != "truth"} | {
                "truth_effects": r["truth"]["effects"]} for r in rows], f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
