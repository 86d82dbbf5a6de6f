#!/usr/bin/env python3
"""A cut in time inside one continuous log (docs/cli.md: fit --until, compensate --from, compare
--cut-at): fit on a log's first cycles and score the rest, every causal state carried across the
cut, as a gyro computer runs it.

    time_cut.py RLGTHERM SCENARIO WORKDIR

Checks, on tests/cli/data/cycles.toml (three chamber cycles, one power-on):
  1. fit --until T gives the coefficient file of a fit on the log written up to T (the same
     bytes): the fit sees the run's head, its states from the one power-on;
  2. compensate --from T scores the samples from T of the run compensated whole: its "bias after"
     is their mean in the -o output (to the CSV's 6 decimals), and the compensation does not start
     again at the cut: with a power-on offset and a rate term, a tail compensated as a power-on of
     its own (what import --split-at makes: a new B0, the rate from zero) differs from it;
  3. compare --cut-at T fits every run before T and scores it from T.
"""

import csv
import json
import os
import subprocess
import sys

T = 28800.0  # s: after two of the three cycles


def run(*args):
    out = subprocess.run(list(args), capture_output=True, text=True)
    if out.returncode not in (0, 4):
        sys.exit(f"{' '.join(args)} exited {out.returncode}:\n{out.stderr}")
    return out.stdout


def main():
    rlg, scenario, work = sys.argv[1:4]
    os.makedirs(work, exist_ok=True)
    data = os.path.join(work, "cycles.csv")
    run(rlg, "simulate", scenario, "-o", data)
    with open(data) as f:
        lines = f.readlines()
    header = [i for i, line in enumerate(lines) if not line.startswith("#")][0]
    names = lines[header].strip().split(",")
    it = names.index("t_s")
    rows = lines[header + 1:]
    head_csv, tail_csv = os.path.join(work, "head.csv"), os.path.join(work, "tail.csv")
    with open(head_csv, "w") as h, open(tail_csv, "w") as t:
        h.writelines(lines[:header + 1])
        t.writelines(lines[:header + 1])
        for r in rows:
            (h if float(r.split(",")[it]) < T else t).write(r)
    failures = []

    # 1. fit --until equals a fit on the head.
    until = os.path.join(work, "until.json")
    on_head = os.path.join(work, "head.json")
    run(rlg, "fit", data, "--model", "poly", "--order", "2", "--offset", "power_on", "--terms",
        "rate,gradient:T2,T1*(T2-T1)", "--until", f"{T:g}", "-o", until)
    run(rlg, "fit", head_csv, "--model", "poly", "--order", "2", "--offset", "power_on", "--terms",
        "rate,gradient:T2,T1*(T2-T1)", "-o", on_head)
    a, b = json.load(open(until)), json.load(open(on_head))
    if a != b:
        failures.append("fit --until differs from the fit on the log's head")

    # 2. compensate --from: the whole run compensated, scored from T.
    comp = os.path.join(work, "comp.csv")
    report = json.loads(run(rlg, "compensate", data, "--coeffs", until, "--from", f"{T:g}", "--json"))
    run(rlg, "compensate", data, "--coeffs", until, "-o", comp)
    with open(comp) as f:
        body = [line for line in f if not line.startswith("#")]
    reader = csv.DictReader(body)
    after = [float(r["bias_comp_dph"]) for r in reader if float(r["t_s"]) >= T]
    mean = sum(after) / len(after)
    got = report["runs"][0]["bias_after_dph"]
    # The CSV holds the compensated bias to 6 decimals: its mean is within 5e-7 of the report's.
    if abs(got - mean) > 5e-7:
        failures.append(f"compensate --from: bias after {got} is not the mean {mean} of the samples from the cut")
    restarted = json.loads(run(rlg, "compensate", tail_csv, "--coeffs", until, "--json"))["runs"][0]
    print(f"held-out third cycle: continued across the cut |bias after| {abs(got):.4f}, 100 s stability "
          f"{report['runs'][0]['stability_100s_after_dph']:.4f} °/h; as a power-on of its own |bias after| "
          f"{abs(restarted['bias_after_dph']):.4f}, 100 s stability {restarted['stability_100s_after_dph']:.4f} °/h")
    if restarted["bias_after_dph"] == got:
        failures.append("compensate --from restarted the compensation at the cut")

    # 3. compare --cut-at fits before the cut and scores after it.
    c = json.loads(run(rlg, "compare", data, "--cut-at", f"{T:g}", "--json"))
    for tr, ho in zip(c["training"], c["heldout"]):
        if not (tr["t_to_s"] < T <= ho["t_from_s"]):
            failures.append(f"compare --cut-at: run {tr['run']} fitted to {tr['t_to_s']} and scored from {ho['t_from_s']}")
    print(f"compare --cut-at {T:g}: {c['split']}; selected {c['selected']['label']}")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
