#!/usr/bin/env python3
"""The documentation's result numbers, generated from the commands that print them.

    python3 tools/readme_numbers.py --write [--bin build/bin/rlgtherm]   # rewrite the generated blocks
    python3 tools/readme_numbers.py --check [--bin build/bin/rlgtherm]   # exit 1 with a diff when a page differs

A generated block lives in one of the pages listed in PAGES (README.md and docs/*.md), between
an opening comment and `<!-- end: NAME -->`. When the block has prose, the prose is the block's
template, in the opening comment on the page itself, and the filled template follows it:

    <!-- generated: NAME
    Held out, it leaves {plus60} °/h at +60 °C; the suite {#passed}passes{/passed}{^passed}FAILS{/passed}.
    -->
    Held out, it leaves 0.0103 °/h at +60 °C; the suite passes.
    <!-- end: NAME -->

The function NAME below runs the rlgtherm commands (build/bin/rlgtherm, or --bin) and returns a
dict of named values: strings (formatted numbers, names, the rows of a table) for the
placeholders {name}, and booleans for the sections, {#name}...{/name} kept when the value is True
and {^name}...{/name} when it is False. A placeholder without a value, a value no placeholder or
section uses, a value of the wrong type, or a brace outside a placeholder is an error: a typo in
a template or a function cannot pass silently. A block without prose, a table whose rows are all
data, opens with `<!-- generated: NAME -->` and its function returns the whole text. To reword a
block, edit its template and run --write.

Every block of BLOCKS must be found in exactly one page, and a page outside PAGES must hold no
block. The numbers are those `bash tools/run.sh` prints (the same scenarios, seeds and options)
plus a few more runs of the same binary; the text around each block names the command. CTest
runs --check (test readme.numbers_current), so the pages cannot drift from the code, and
tests/cli/readme_numbers_templates.py checks that a faulty template is refused (test
readme.numbers_templates). Measured speeds and the long blind diagnosis tests give their own
commands.
"""

import argparse
import csv
import difflib
import json
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TCLAB = os.path.join(ROOT, "data", "tclab")

# The pages that may hold generated blocks, relative to ROOT.
PAGES = [
    "README.md",
    "docs/architecture.md",
    "docs/cli.md",
    "docs/data-format.md",
    "docs/diagnosis.md",
    "docs/performance.md",
    "docs/plan.md",
    "docs/python.md",
    "docs/results.md",
    "docs/testing.md",
    "docs/validation.md",
]
# The nine runs Eq. (2) is fitted on in paper-suite.toml ([[fits]] "fixed" and [pairs]); +60 °C is held out.
TRAINING_RUNS = ",".join(f"fixed{t:+d}" for t in range(-30, 60, 10))


class Runner:
    def __init__(self, binary, tmp):
        self.binary = binary
        self.tmp = tmp
        self.cache = {}

    def run(self, *args):
        key = tuple(args)
        if key not in self.cache:
            out = subprocess.run([self.binary, *args], cwd=ROOT, capture_output=True, text=True)
            if out.returncode not in (0, 4):
                sys.exit(f"readme_numbers: rlgtherm {' '.join(args)} exited {out.returncode}:\n{out.stderr}")
            self.cache[key] = out.stdout
        return self.cache[key]

    def json(self, *args):
        return json.loads(self.run(*args, "--json"))

    def path(self, name):
        return os.path.join(self.tmp, name)

    def simulate(self, scenario, seed=None):
        name = os.path.basename(scenario).replace(".toml", f"-{seed}.csv" if seed else ".csv")
        out = self.path(name)
        if not os.path.exists(out):
            self.run("simulate", scenario, *(["--seed", str(seed)] if seed else []), "-o", out)
        return out

    def validate(self):
        return self.json("validate", "scenarios/paper-suite.toml")


def f(x, d):
    """A signed number with d decimals, the minus sign typographic."""
    return f"{x:+.{d}f}".replace("-", "−")


def u(x, d):
    """An unsigned number with d decimals (typographic minus when negative)."""
    return f"{x:.{d}f}".replace("-", "−")


def span(values, d, signed=False):
    lo, hi = min(values), max(values)
    fmt = f if signed else u
    return f"{fmt(lo, d)} … {fmt(hi, d)}"


def fixed_rows(v):
    return [r for r in v["table2"] if r["fit"] == "fixed"]


def held_out_fixed(v):
    return [r for r in fixed_rows(v) if r["run"] == "fixed+60"]


def temperature_rise(csv_path, run_id, column, window_s=60.0):
    """Mean over the run's last minute less the mean over its first minute (°C)."""
    t, x = [], []
    with open(csv_path) as fh:
        for row in csv.DictReader(line for line in fh if not line.startswith("#")):
            if row["run"] == run_id:
                t.append(float(row["t_s"]))
                x.append(float(row[column]))
    first = [v for s, v in zip(t, x) if s < t[0] + window_s]
    last = [v for s, v in zip(t, x) if s > t[-1] - window_s]
    return sum(last) / len(last) - sum(first) / len(first)


# ---- blocks ----------------------------------------------------------------------------------

def paper_table(r):
    v = r.validate()
    fixed = fixed_rows(v)
    fitted = [x for x in fixed if x["run"] != "fixed+60"]
    plus60 = held_out_fixed(v)[0]
    pf = r.simulate("scenarios/paper-fixed.toml")
    arw = [x["arw_deg_per_sqrt_h"] for x in fixed if x["arw_deg_per_sqrt_h"] is not None]
    bi = [x["bias_instability_dph"] for x in fixed if x["bias_instability_dph"] is not None]
    bi_bound = [x["not_resolved"]["bias_instability_dph"]["upper_bound"] for x in fixed
                if x["bias_instability_dph"] is None]
    t1 = v["table1"]
    sse = " ".join(u(t1[f"M{i}"], 4) for i in range(1, 7))
    # The page says `pairs` on the nine training runs at 60 s prints this row: hold it to that.
    pairs = r.json("pairs", pf, "--runs", TRAINING_RUNS, "--average", "60")["combinations"]
    pairs_sse = " ".join(u(pairs[f"M{i}"]["sse_ave"], 4) for i in range(1, 7))
    if pairs_sse != sse:
        sys.exit(f"readme_numbers: validate's Table 1 ({sse}) differs from `pairs --runs {TRAINING_RUNS} "
                 f"--average 60` ({pairs_sse})")
    return {"rise1": u(temperature_rise(pf, "fixed+0", "T1"), 2), "rise2": u(temperature_rise(pf, "fixed+0", "T2"), 2),
            "bias_before": span([x["bias_before_dph"] for x in fixed], 2),
            "averaging": f"{fixed[0]['stability_averaging_s']:g}",
            "stability_before": span([x["stability_before_dph"] for x in fixed], 3),
            "stability_after": span([x["stability_after_dph"] for x in fixed], 3),
            "bias_fitted": span([x["bias_after_dph"] for x in fitted], 4, signed=True),
            "bias_held_out": f(plus60["bias_after_dph"], 4),
            "stability_100s": span([x["stability_100s_after_dph"] for x in fixed], 4),
            "sse": sse, "best_pair": v["best_pair"], "arw": span(arw, 5), "runs": str(len(fixed)),
            "resolved": bool(bi), "resolved_runs": str(len(bi)), "instability": span(bi, 4) if bi else "",
            "both": bool(bi) and bool(bi_bound),
            "unresolved": bool(bi_bound), "unresolved_runs": str(len(bi_bound)),
            "bound": span(bi_bound, 4) if bi_bound else ""}


def sse_ratio(r):
    m1 = r.validate()["table1"]["M1"]
    return {"ratio": f"{2.0515 / m1:.0f}"}


def bias_after_claim(r):
    v = r.validate()
    fixed = fixed_rows(v)
    missed = [x for x in fixed if abs(x["bias_after_dph"]) > 0.01]
    checks = [c for c in v["checks"] if c["check"] == "bias after" and c["run"].startswith("fixed")]
    return {"b0": span([x["b0_error_dph"] for x in fixed], 4),
            "missed": bool(missed),
            "one_missed": len(missed) == 1,
            "missed_runs": ", ".join(f"{x['run']} ({f(x['bias_after_dph'], 4)})" for x in missed),
            "passed": str(sum(c["passed"] for c in checks)),
            "checks": str(len(checks))}


def m1_seeds(r):
    wins, leads = 0, []
    seeds = range(1, 17)
    for seed in seeds:
        p = r.json("pairs", r.simulate("scenarios/paper-fixed.toml", seed), "--runs", TRAINING_RUNS, "--average", "60")
        sse = {k: c["sse_ave"] for k, c in p["combinations"].items()}
        ranked = sorted(sse, key=sse.get)
        if ranked[0] == "M1":
            wins += 1
            leads.append(100.0 * (sse[ranked[1]] / sse["M1"] - 1.0))
    return {"wins": str(wins), "seeds": str(len(seeds)), "won": bool(leads),
            "lead": f"{min(leads):.0f}–{max(leads):.0f}" if leads else ""}


def run_ids(csv_path):
    """The run ids of a tidy CSV, in file order."""
    ids = []
    with open(csv_path) as fh:
        for row in csv.DictReader(line for line in fh if not line.startswith("#")):
            if not ids or ids[-1] != row["run"]:
                ids.append(row["run"])
    return ids


def merged_csv(r, name, paths):
    """The runs of several simulated CSVs in one file (same columns)."""
    out = r.path(name)
    if not os.path.exists(out):
        with open(out, "w") as dst:
            for i, p in enumerate(paths):
                with open(p) as src:
                    lines = [line for line in src if not line.startswith("#")]
                dst.writelines(lines if i == 0 else lines[1:])
    return out


def suite_shows(r):
    v = r.validate()
    varying = [x for x in v["table2"] if x["fit"] == "varying"]
    fixed_csv = r.simulate("scenarios/paper-fixed.toml")
    ramps_csv = r.simulate("scenarios/ramps.toml")
    train_csv = r.simulate("scenarios/varying-train.toml")
    fixed_runs = TRAINING_RUNS
    # One model for both regimes: fitted on the fixed runs alone, applied to the ramps.
    only_fixed = r.path("only-fixed.json")
    r.run("fit", fixed_csv, "--runs", fixed_runs, "-o", only_fixed)
    on_ramps = r.json("compensate", ramps_csv, "--coeffs", only_fixed)["runs"]
    # ... and fitted on both regimes jointly, applied to the fixed runs.
    both_csv = merged_csv(r, "fixed-and-train.csv", [fixed_csv, train_csv])
    joint = r.path("joint.json")
    train_runs = ",".join(run_ids(train_csv))
    r.run("fit", both_csv, "--runs", fixed_runs + "," + train_runs, "-o", joint)
    on_fixed = [x for x in r.json("compensate", fixed_csv, "--coeffs", joint)["runs"] if x["run"] != "fixed+60"]
    return {"stability_before": span([x["stability_before_dph"] for x in varying], 1),
            "stability_after": span([x["stability_after_dph"] for x in varying], 2),
            "bias_after": span([x["bias_after_dph"] for x in varying], 3, signed=True),
            "peak": span([x["peak_abs_100s_after_dph"] for x in varying], 2),
            "fixed_model_on_ramps": span([x["bias_after_dph"] for x in on_ramps], 0, signed=True),
            "joint_model_on_fixed": span([abs(x["bias_after_dph"]) for x in on_fixed], 3)}


def model_form(m):
    """A fitted model's terms after its order and offset: "+ gradient T2 + T1*(T2-T1)"."""
    return "".join(" + " + (t.get("name") or ("gradient " + t["channel"] if t["term"] == "gradient" else t["term"]))
                   for t in m["terms"])


def service_model(r):
    """docs/results.md: one auto model for fixed and varying ambients (scenarios/service-suite.toml),
    and the same search on the fixed warm-ups alone, compensating the ramps."""
    v = r.json("validate", "scenarios/service-suite.toml")
    m = v["coefficients"]["service"]
    rows = {x["run"]: x for x in v["table2"]}
    held = ["fixed+60", "ramp20to60", "ramp20to50", "rise-fall", "fall-rise"]
    ramps = held[1:]
    trained = [x for x in v["table2"] if x["run"] not in held]
    # The same search on the fixed warm-ups alone, then the ramps compensated.
    fixed_csv = r.simulate("scenarios/paper-fixed.toml")
    ramps_csv = r.simulate("scenarios/ramps.toml")
    soaks_only = r.path("auto-fixed-only.json")
    r.run("fit", fixed_csv, "--runs", TRAINING_RUNS, "--model", "auto", "-o", soaks_only)
    on_ramps = r.json("compensate", ramps_csv, "--coeffs", soaks_only)["runs"]
    with open(soaks_only) as fh:
        s = json.load(fh)
    return {"order": str(m["order"]), "channel": m["channel"], "offset": m["offset"].replace("_", "-"),
            "terms": model_form(m),
            "plus60": f"{abs(rows['fixed+60']['bias_after_dph']):.4f}",
            "ramps": span([abs(rows[k]["bias_after_dph"]) for k in ramps], 4),
            "held_stability": span([rows[k]["stability_100s_after_dph"] for k in held], 4),
            "trained_bias": span([abs(x["bias_after_dph"]) for x in trained], 4),
            "trained_stability": span([x["stability_100s_after_dph"] for x in trained], 4),
            "passed": bool(v["passed"]),
            "soaks_order": str(s["order"]), "soaks_offset": s["offset"].replace("_", "-"),
            "soaks_terms": model_form(s),
            "soaks_on_ramps": span([abs(x["bias_after_dph"]) for x in on_ramps], 2)}


def worked_example(r):
    csv_path = r.simulate("scenarios/example-hidden-rate.toml")
    d = r.json("diagnose", csv_path, "--gyro", "scenarios/gyros/default.toml")
    a = d["accepted"][0]
    return {"cause": a["cause"], "target": a["target"], "k": f"{a['parameters']['k_dph_per_C_per_min']:.4f}",
            "ratio": f"{a['heldout_rms_ratio']:.2f}",
            "residuals": ", ".join(f"{c} {v * 1e3:.1f} mK"
                                   for c, v in sorted(d["baseline"]["temperature_rms_C"].items()))}


TCLAB_FILES = ["mimo_2nd_order_600s.txt", "mimo_energy_balance_600s.txt", "mimo_hybrid_600s.txt",
               "mimo_mhe_nonlinear_noheader.txt"]


def tclab_csv(r, files, name):
    out = r.path(name)
    if not os.path.exists(out):
        r.run("import", "tclab", *[os.path.join(TCLAB, x) for x in files], "-o", out)
    return out


def describe(cause, params):
    p = dict(params)
    if cause == "sensor.lag":
        return f"τ = {p['time_constant_s']:.1f} s"
    if cause == "sensor.offset":
        return f"{f(p['offset_C'], 2)} °C"
    if cause == "thermal.power_drift":
        return f"g = {u(p['g_per_C'], 3)} /°C"
    if cause == "thermal.missing_link":
        return f"G = {p['conductance_W_per_K']:.4f} W/K"
    if cause == "thermal.radiation":
        return f"εA = {p['emissivity_area_m2'] * 1e4:.1f} cm²"
    return ", ".join(f"{k} = {v:.3g}" for k, v in p.items())


def step_table(d):
    channels = sorted(d["baseline"]["temperature_rms_C"])
    head = "| step | accepted | parameters | " + " | ".join(f"{c} RMS" for c in channels) + " | held-out ratio |"
    rows = [head, "|---" * (4 + len(channels)) + "|",
            "| baseline | calibrated two-node linear model | | " +
            " | ".join(f"{d['baseline']['temperature_rms_C'][c]:.3f} °C" for c in channels) + " | |"]
    for i, a in enumerate(d["accepted"], 1):
        stand_in = "" if a["plausible"] else " (stand-in: outside the catalog's range)"
        rows.append(f"| {i} | `{a['cause']}` {a['target']} | {describe(a['cause'], a['parameters'])}{stand_in} | " +
                    " | ".join(f"{a['after']['temperature_rms_C'][c]:.3f} °C" for c in channels) +
                    f" | {a['heldout_rms_ratio']:.2f} |")
    return "\n".join(rows)


def tclab_all(r):
    d = r.json("diagnose", tclab_csv(r, TCLAB_FILES, "tclab.csv"), "--gyro", "scenarios/gyros/tclab-nominal.toml",
               "--per-run-gains")
    return step_table(d)


def tclab_candidates(r):
    d = r.json("diagnose", tclab_csv(r, TCLAB_FILES, "tclab.csv"), "--gyro", "scenarios/gyros/tclab-nominal.toml",
               "--per-run-gains")
    rows = ["| candidate | target | refitted | parameters | score | held-out ratio |", "|---|---|---|---|---|---|"]
    for c in d["candidates"]:
        if c["kind"] == "thermal":
            rows.append(f"| `{c['cause']}` | {c['target']} | yes | {describe(c['cause'], c['parameters'])} | "
                        f"{c['score']:.1f} | {c['heldout_rms_ratio']:.2f} |")
        else:  # screened only (or refitted to nothing): the linearised gain, no held-out test
            rows.append(f"| `{c['cause']}` | {c['target']} | {c['kind'].replace('thermal ', '')[1:-1]} | | "
                        f"{c['score']:.1f} | |")
    return "\n".join(rows)


def tclab_physics(r):
    """APMonitor's TCLab energy balance (U = 10 W/(m² K), A = 10 cm² to room air per heater, As = 2 cm²
    between the sinks, emissivity 0.9; their second-order models add a sensor state) against what
    diagnose finds on the four logs from the nominal without any of it."""
    d = r.json("diagnose", tclab_csv(r, TCLAB_FILES, "tclab.csv"), "--gyro", "scenarios/gyros/tclab-nominal.toml",
               "--per-run-gains")
    knobs = {k["name"]: k for k in d["calibration"]["knobs"]}
    steps = {(a["cause"], a["target"]): (i, a) for i, a in enumerate(d["accepted"], 1)}
    cands = {(c["cause"], c["target"]): c for c in d["candidates"]}

    def found(cause, target):
        """What became of one cause: accepted, refitted, screened, or not a candidate."""
        if (cause, target) in steps:
            i, a = steps[(cause, target)]
            return (f"accepted at step {i}: {describe(cause, a['parameters'])}"
                    f"{'' if a['plausible'] else ' (outside the catalog range: a stand-in)'}")
        c = cands.get((cause, target))
        if c is None:
            return "not a candidate"
        if c["kind"] == "thermal":
            return (f"not accepted: refitted to {describe(cause, c['parameters'])}, score {c['score']:.1f}, "
                    f"held-out ratio {c['heldout_rms_ratio']:.2f} in the first search")
        return f"not accepted: screened at {c['score']:.1f} in the first search, not refitted"

    def conv(node):
        k = knobs[f"G:{node}-ambient"]
        return f"{k['calibrated']:.4f} W/K ({k['shift_sigma']:+.1f} prior sd from {k['nominal']:g})"

    return {"convection_1": conv("heater1"), "convection_2": conv("heater2"),
            "radiation_1": found("thermal.radiation", "heater1-ambient"),
            "radiation_2": found("thermal.radiation", "heater2-ambient"),
            "link": found("thermal.missing_link", "heater1-heater2"),
            "radiation_12": found("thermal.radiation", "heater1-heater2"),
            "lag_1": found("sensor.lag", "T1"), "lag_2": found("sensor.lag", "T2"),
            "offset_1": found("sensor.offset", "T1"), "offset_2": found("sensor.offset", "T2")}


def tclab_fit_one(r):
    d = r.json("diagnose", tclab_csv(r, TCLAB_FILES, "tclab.csv"), "--gyro", "scenarios/gyros/tclab-nominal.toml",
               "--per-run-gains", "--fit-runs", "mimo_energy_balance_600s")
    return step_table(d)


def tclab_one_run(r):
    d = r.json("diagnose", tclab_csv(r, ["mimo_energy_balance_600s.txt"], "tclab-one.csv"), "--gyro",
               "scenarios/gyros/tclab-nominal.toml")
    split = next(n for n in d["notes"] if n.startswith("one run, held out in time"))
    m = re.match(r"one run, held out in time: fitted on (t = .*? s), scored on (t = .*? s)$", split)
    best = d["candidates"][0]
    a = d["accepted"][0] if d["accepted"] else best
    return {"fitted": m.group(1), "scored": m.group(2), "accepted": bool(d["accepted"]),
            "cause": a["cause"], "target": a["target"], "parameters": describe(a["cause"], a["parameters"]),
            "ratio": f"{a['heldout_rms_ratio']:.2f}", "score": f"{best['score']:.0f}"}


def population(r):
    """scenarios/paper-population.toml; the share of gyros whose best pair is M1 comes from the
    same suite with best_pair = "M1" checked (the same gyros and seeds: the other numbers agree)."""
    src = open(os.path.join(ROOT, "scenarios/paper-population.toml")).read()
    path = r.path("population-m1.toml")
    with open(path, "w") as out:
        out.write(src.replace('scenarios = ["paper-fixed.toml"]',
                              f'scenarios = ["{os.path.join(ROOT, "scenarios/paper-fixed.toml")}"]')
                 .replace("max_failing_fraction = 0.05", 'max_failing_fraction = 0.05\nbest_pair = "M1"'))
    p = r.json("validate", path)["population"]
    n = p["gyros"]
    # The yield of the suite as bundled (the copy above also checks the best pair).
    bundled_yield = r.json("validate", "scenarios/paper-population.toml")["population"]["yield"]
    metric = {(m["run"], m["metric"]): m for m in p["metrics"]}
    check = {(c["check"], c["run"]): c for c in p["checks"]}
    inside = [f"fixed{t:+d}" for t in range(-30, 60, 10)]

    def dist(run, name, d=4):
        m = metric[(run, name)]
        return f"{m['median']:.{d}f} / {m['p95']:.{d}f} / {m['worst']:.{d}f} (gyro {m['worst_gyro']})"

    def fails(name, runs):
        values = [100.0 * check[(name, x)]["failed_gyros"] / n for x in runs]
        return f"{values[0]:.1f}" if len(values) == 1 else span(values, 1)

    return {"rows": "\n".join(f"| {run} | {dist(run, 'abs_bias_before_dph', 3)} | {dist(run, 'abs_bias_after_dph')} | "
                              f"{dist(run, 'stability_100s_after_dph')} |" for run in ("fixed+0", "fixed+50", "fixed+60")),
            "gyros": f"{n:,}",
            "bias_inside": fails("bias after", inside), "stability_inside": fails("stability 100s", inside),
            "bias_60": fails("bias after", ["fixed+60"]), "stability_60": fails("stability 100s", ["fixed+60"]),
            "passing": f"{bundled_yield['passing_gyros']:,}", "yield": f"{100.0 * bundled_yield['fraction']:.1f}",
            "m1": f"{100.0 * (n - check[('best pair', '')]['failed_gyros']) / n:.1f}",
            "worst_gyro": str(metric[("fixed+60", "abs_bias_after_dph")]["worst_gyro"])}


def cli_tour(r):
    """README's five-command tour, run as written: paper-fixed.toml at its own seed, the fit on
    the nine training runs, compensate of all ten, and the TCLab diagnosis of tools/run.sh."""
    pf = r.simulate("scenarios/paper-fixed.toml")
    coeffs = r.path("tour-coeffs.json")
    if not os.path.exists(coeffs):
        r.run("fit", pf, "--runs", TRAINING_RUNS, "-o", coeffs)
    plus60 = [x for x in r.json("compensate", pf, "--coeffs", coeffs)["runs"] if x["run"] == "fixed+60"][0]
    best = r.run("pairs", pf, "--runs", TRAINING_RUNS, "--average", "60").strip().splitlines()[-1]
    d = r.json("diagnose", tclab_csv(r, TCLAB_FILES, "tclab.csv"), "--gyro", "scenarios/gyros/tclab-nominal.toml",
               "--per-run-gains")
    # The accepted steps as the tour lists them.
    names = {"sensor.lag": "a lag of sensor {t}", "thermal.missing_link": "a link {t}",
             "thermal.power_drift": "a power drift of {t}", "thermal.radiation": "radiation of {t}",
             "thermal.missing_mass": "a mass at {t}", "sensor.offset": "an offset of sensor {t}"}
    steps = [names.get(a["cause"], a["cause"] + " on {t}").format(t=a["target"]) for a in d["accepted"]]
    n = len(steps)
    return {"best": best, "before": f"{plus60['bias_before_dph']:.4f}", "after": f(plus60["bias_after_dph"], 4),
            "count": {1: "one", 2: "two", 3: "three", 4: "four"}.get(n, str(n)), "plural": n != 1,
            "steps": ", ".join(steps)}


IMU = os.path.join(ROOT, "data", "imu-thermal-cycle", "imu_raw_data.csv")


def imu_csv(r, axis):
    """One gyro axis of the IMU log as the tidy CSV, imported as docs/cli.md shows."""
    out = r.path(f"imu-{axis}.csv")
    if not os.path.exists(out):
        r.run("import", "columns", IMU, "--time", "timestamp:us", "--temp", "imu.temperature", "--rate",
              f"imu.gyro.{axis}:dps", "--run", f"imu-{axis}", "-o", out)
    return out


def white_noise(csv_path, column="bias_dph"):
    """1 sigma of a sample's white noise: the sd of first differences over sqrt(2) (°/h)."""
    with open(csv_path) as fh:
        x = [float(row[column]) for row in csv.DictReader(line for line in fh if not line.startswith("#"))]
    d = [b - a for a, b in zip(x, x[1:])]
    mean = sum(d) / len(d)
    return (sum((v - mean) ** 2 for v in d) / (len(d) - 1) / 2) ** 0.5


def imu_models(r):
    """docs/results.md: PX4's and ArduPilot's cubics and the model compare selects, per axis."""
    rows, ratios, supported = [], {}, {}
    split = ""
    for axis in "xyz":
        path = imu_csv(r, axis)
        d = r.json("compare", path)
        split = d["split"]
        by = {m["label"]: m for m in d["models"]}
        sel = by[d["selected"]["label"]]
        px4, ap = by["px4"]["heldout_rms_dph"], by["ardupilot"]["heldout_rms_dph"]
        ratios[axis] = sel["heldout_rms_dph"] / px4
        supported[axis] = d["selected"]["supported"]
        rows.append(f"| {axis} | {white_noise(path):.2f} | {px4:.1f} | {ap:.1f} | {sel['heldout_rms_dph']:.1f}: "
                    f"{d['selected']['label']} ({sel['cv_rms_dph']:.1f}) | {ratios[axis]:.2f} | "
                    f"{d['selected']['heldout_over_cv']:.1f} |")
    better = [a for a, v in ratios.items() if v <= 0.75]
    worse = [a for a, v in ratios.items() if v > 1.10]
    unsupported = [a for a, ok in supported.items() if not ok]
    return {"split": split, "rows": "\n".join(rows),
            "better_count": str(len(better)), "better": ", ".join(better) if better else "none",
            "any_worse": bool(worse), "worse": ", ".join(worse),
            "selection_holds": not worse and len(better) >= 2,
            "any_unsupported": bool(unsupported), "unsupported": ", ".join(unsupported)}


def population_models(r):
    """docs/results.md: Eq. (2) against the single-sensor forms on gyros of the paper population."""
    count = 12
    scenario = r.path("population-fixed.toml")
    if not os.path.exists(scenario):
        with open(os.path.join(ROOT, "scenarios", "paper-fixed.toml")) as fh:
            fixed = fh.read().replace('gyro = "gyros/default.toml"',
                                      f'gyro = "{os.path.join(ROOT, "scenarios", "gyros", "default.toml")}"')
        with open(os.path.join(ROOT, "scenarios", "paper-population.toml")) as fh:
            text = fh.read()
        population = text[text.index("[population]"):].replace("count = 1000", f"count = {count}")
        with open(scenario, "w") as fh:
            fh.write(fixed + "\n" + population)
    nominal = r.json("compare", r.simulate("scenarios/paper-fixed.toml"), "--fit-runs", TRAINING_RUNS)
    nby = {m["label"]: m for m in nominal["models"]}
    wins = {"px4": 0, "ardupilot": 0, "auto": 0}
    selected_eq2 = 0
    eq2_rms, px4_rms = [], []
    for i in range(count):
        data = r.path(f"population-gyro-{i}.csv")
        if not os.path.exists(data):
            r.run("simulate", scenario, "--gyro", str(i), "-o", data)
        d = r.json("compare", data, "--fit-runs", TRAINING_RUNS)
        by = {m["label"]: m for m in d["models"]}
        eq2 = by["guo2006 (T1, T2)"]["heldout_rms_dph"]
        eq2_rms.append(eq2)
        px4_rms.append(by["px4"]["heldout_rms_dph"])
        for name in wins:
            wins[name] += eq2 < by[name]["heldout_rms_dph"]
        selected_eq2 += d["selected"]["model"] == "guo2006"
    return {"nominal_eq2": u(nby["guo2006 (T1, T2)"]["heldout_rms_dph"], 4),
            "nominal_px4": u(nby["px4"]["heldout_rms_dph"], 4),
            "nominal_ardupilot": u(nby["ardupilot"]["heldout_rms_dph"], 4),
            "nominal_selected": u(nby[nominal["selected"]["label"]]["heldout_rms_dph"], 4),
            "selected": nominal["selected"]["label"],
            "count": str(count), "last": str(count - 1),
            "wins_px4": str(wins["px4"]), "wins_ardupilot": str(wins["ardupilot"]), "wins_auto": str(wins["auto"]),
            "eq2": span(eq2_rms, 4), "px4": span(px4_rms, 4), "selected_eq2": str(selected_eq2)}


PLAN = "scenarios/plan-default.toml"


def interval(iv, d=4):
    lo, hi = iv
    return f"[{'−∞' if lo is None else f'{lo:.{d}f}'}, {'∞' if hi is None else f'{hi:.{d}f}'}]"


def plan_tables(p):
    """A plan's JSON as the values of its two tables: the candidates' rows (numbered as the points
    of pareto.png), the number of gyros, and the table of the p95 per service run."""
    rows, k = [], 0
    for c in p["candidates"]:
        if c["p95_abs_bias_after_dph"] is None:
            rows.append(f"| | {c['name']} | {c['chamber_h']:.1f} | cannot be fitted with {c['model']} | | | | | | | |")
            continue
        k += 1
        scr = c["screen"]
        rows.append(f"| {k} | {c['name']} | {c['chamber_h']:.1f} | {c['p95_abs_bias_after_dph']:.4f} "
                    f"{interval(c['p95_interval_dph'])} | {c['median_abs_bias_after_dph']:.4f} | "
                    f"{c['worst_abs_bias_after_dph']:.4f} | {c['p95_stability_100s_after_dph']:.4f} | "
                    f"{scr['p95_abs_bias_after_dph']:.4f} | {scr['mc_to_screen_p95']:.2f} | {c['meets_target']} | "
                    f"{'yes' if c['pareto'] else ''} |")
    ids = [s["id"] for s in p["service"]]
    per = [f"| {c['name']} | " + " | ".join(f"{s['p95_abs_bias_after_dph']:.4f}" for s in c["service"]) + " |"
           for c in p["candidates"] if c["service"] is not None]
    return {"candidates": "\n".join(rows), "gyros": str(p["gyros"]),
            "service": "| candidate | " + " | ".join(ids) + " |\n|---|" + "---|" * len(ids) + "\n" + "\n".join(per)}


def plan_default(r):
    """`plan scenarios/plan-default.toml`: its tables and the command's one-line answer."""
    p = r.json("plan", PLAN)
    # The text's last line is in the JSON too (one run of the plan for both).
    return {**plan_tables(p), "answer": p["answer"]}


def plan_verified(r, path):
    """`plan PATH --verify 200`: its tables, the verification and the answer."""
    p = r.json("plan", path, "--verify", "200")
    v = p["verify"]
    return {**plan_tables(p), "answer": p["answer"], "verified_gyros": str(v["gyros"]),
            "verified_candidate": v["candidate"],
            "realised": f"{v['realised_p95_dph']:.4f} {interval(v['realised_interval_dph'])}",
            "predicted": f"{v['predicted_p95_dph']:.4f} {interval(v['predicted_interval_dph'])}",
            "consistent": bool(v["consistent"])}


def plan_soaks(r):
    return plan_verified(r, "scenarios/plan-soaks.toml")


def plan_service(r):
    return plan_verified(r, "scenarios/plan-service.toml")


def plan_screen_noise_only(r):
    """The screen against the Monte Carlo where the screen's assumptions hold: the nominal gyro
    with its noise alone (tests/data/plan/small.toml)."""
    p = r.json("plan", "tests/data/plan/small.toml")
    ratios = [c["screen"]["mc_to_screen_p95"] for c in p["candidates"] if c["screen"]["mc_to_screen_p95"] is not None]
    return {"gyros": str(p["gyros"]), "ratio": span(ratios, 2)}


def plan_answers(r):
    """The questions the default plan answers, from the same JSON."""
    p = r.json("plan", PLAN)
    c = {x["name"]: x for x in p["candidates"]}
    fitted = [x for x in p["candidates"] if x["p95_abs_bias_after_dph"] is not None]
    paper = c["paper-nine-soaks"]
    hi = paper["p95_interval_dph"][1]
    # The paper's protocol with the paper's model: the cheapest candidate fitting the same model
    # that is not shown worse, its p95 at or below the upper end of the paper's interval.
    fitted = [x for x in fitted if x["model"] == paper["model"]]
    same = min((x for x in fitted if x["p95_abs_bias_after_dph"] <= hi), key=lambda x: (x["chamber_h"], x["name"]))

    def service(x, sid):
        return next(s for s in x["service"] if s["id"] == sid)

    s60 = service(paper, "soak+60")
    same60 = min((x for x in fitted if service(x, "soak+60")["p95_abs_bias_after_dph"] <= s60["p95_interval_dph"][1]),
                 key=lambda x: (x["chamber_h"], x["name"]))
    ramps = [s["id"] for s in p["service"] if s["id"].startswith("ramp")]

    def leaves(name):
        """One protocol's clause of the list of what each leaves."""
        x = c[name]
        if x["p95_abs_bias_after_dph"] is None:
            return f"`{name}` cannot be fitted with Eq. (2) (one power-on fixes T10)"
        ramp = " and ".join(f"{service(x, s)['p95_abs_bias_after_dph']:.4f}" for s in ramps)
        return (f"`{name}` leaves {service(x, 'soak+60')['p95_abs_bias_after_dph']:.4f} °/h at +60 °C and "
                f"{ramp} °/h on the two ramps")

    builtins = [x["name"] for x in p["candidates"] if x["builtin"] == x["name"]]
    variants = [x["name"] for x in p["candidates"] if x["builtin"] and x["builtin"] != x["name"]]
    return {"paper_h": f"{paper['chamber_h']:.1f}",
            "paper_p95": f"{paper['p95_abs_bias_after_dph']:.4f} °/h {interval(paper['p95_interval_dph'])}",
            "same": same["name"], "same_h": f"{same['chamber_h']:.1f}",
            "same_p95": f"{same['p95_abs_bias_after_dph']:.4f}",
            "saved": f"{paper['chamber_h'] - same['chamber_h']:.1f}",
            "paper_60": f"{s60['p95_abs_bias_after_dph']:.4f} °/h {interval(s60['p95_interval_dph'])}",
            "same_60": same60["name"], "same_60_h": f"{same60['chamber_h']:.1f}",
            "same_60_p95": f"{service(same60, 'soak+60')['p95_abs_bias_after_dph']:.4f}",
            "saved_60": f"{paper['chamber_h'] - same60['chamber_h']:.1f}",
            "builtins": "; ".join(leaves(n) for n in builtins), "variants": "; ".join(leaves(n) for n in variants)}


BLOCKS = {
    "imu-models": imu_models,
    "population-models": population_models,
    "cli-tour": cli_tour,
    "paper-table": paper_table,
    "sse-ratio": sse_ratio,
    "bias-after-claim": bias_after_claim,
    "m1-seeds": m1_seeds,
    "suite-shows": suite_shows,
    "service-model": service_model,
    "tclab-all": tclab_all,
    "worked-example": worked_example,
    "tclab-candidates": tclab_candidates,
    "tclab-physics": tclab_physics,
    "tclab-fit-one": tclab_fit_one,
    "tclab-one-run": tclab_one_run,
    "population": population,
    "plan-default": plan_default,
    "plan-answers": plan_answers,
    "plan-service": plan_service,
    "plan-screen-noise-only": plan_screen_noise_only,
    "plan-soaks": plan_soaks,
}


# ---- templates -------------------------------------------------------------------------------

# A block on a page: its name, its template (None when it opens with `<!-- generated: NAME -->`)
# and its text.
MARK = re.compile(r"<!-- generated: ([a-z0-9-]+)(?: -->\n|\n(.*?)\n-->\n)(.*?)<!-- end: \1 -->", flags=re.S)
OPENING = re.compile(r"<!-- generated: ([a-z0-9-]+)(?: -->|\n)")
# A placeholder {name}, or a section's opening {#name} or {^name} or its end {/name}.
TOKEN = re.compile(r"\{([#^/]?)([a-z][a-z0-9_]*)\}")


def template_names(template):
    """{name: "value" or "section"} of a template, after checking its syntax: every brace is part
    of a token and every section closes, innermost first."""
    names, open_sections = {}, []
    for piece in re.split(r"(\{[^{}]*\})", template):
        token = TOKEN.fullmatch(piece)
        if not token:
            if "{" in piece or "}" in piece:
                raise ValueError(f"'{piece}' is not a placeholder: {{name}}, {{#name}}, {{^name}} or {{/name}}")
            continue
        kind, name = token.groups()
        if kind == "/":
            if not open_sections or open_sections.pop() != name:
                raise ValueError(f"{{/{name}}} closes no open section {{#{name}}} or {{^{name}}}")
            continue
        use = "section" if kind else "value"
        if names.setdefault(name, use) != use:
            raise ValueError(f"'{name}' is both a value and a section")
        if kind:
            open_sections.append(name)
    if open_sections:
        raise ValueError(f"section '{open_sections[-1]}' is not closed with {{/{open_sections[-1]}}}")
    return names


def fill(template, values):
    """The template with its {name} replaced by values[name] (a string) and each {#name}...{/name}
    kept when values[name] is True, each {^name}...{/name} when it is False. A name the template
    uses that values lacks, a value it does not use, or a value of the wrong type is an error."""
    names = template_names(template)
    unknown = sorted(set(names) - set(values))
    unused = sorted(set(values) - set(names))
    if unknown or unused:
        raise ValueError("; ".join(([f"the template names {', '.join(unknown)}, which the script does not give"]
                                    if unknown else []) +
                                   ([f"the script gives {', '.join(unused)}, which the template does not use"]
                                    if unused else [])))
    for name, use in names.items():
        want = bool if use == "section" else str
        if type(values[name]) is not want:
            raise ValueError(f"'{name}' is a {use}: its value must be a {want.__name__}, "
                             f"not {type(values[name]).__name__}")

    def section(m):
        kind, name, body = m.groups()
        return body if values[name] == (kind == "#") else ""

    while True:
        text = re.sub(r"\{([#^])([a-z0-9_]+)\}((?:(?!\{[#^]).)*?)\{/\2\}", section, template, flags=re.S)
        if text == template:
            break
        template = text
    return TOKEN.sub(lambda m: values[m.group(2)], template)


def pages_and_blocks():
    """{page: text} of PAGES, after checking that every block lives in exactly one of them."""
    texts = {}
    for page in PAGES:
        path = os.path.join(ROOT, page)
        if not os.path.exists(path):
            sys.exit(f"readme_numbers: {page} is listed in PAGES but does not exist")
        with open(path) as fh:
            texts[page] = fh.read()
    where = {}
    for page, text in texts.items():
        for name in OPENING.findall(text):
            if name not in BLOCKS:
                sys.exit(f"readme_numbers: {page} has a block '{name}' this script does not make")
            where.setdefault(name, []).append(page)
        if len(OPENING.findall(text)) != len(MARK.findall(text)):
            sys.exit(f"readme_numbers: {page} has a '<!-- generated: NAME' without its closing '-->' or "
                     "its '<!-- end: NAME -->'")
    for name in BLOCKS:
        if name not in where:
            sys.exit(f"readme_numbers: block '{name}' is in none of {', '.join(PAGES)}")
        if len(where[name]) > 1:
            sys.exit(f"readme_numbers: block '{name}' is in more than one place: {', '.join(where[name])}")
    listed = {os.path.normpath(p) for p in PAGES}
    candidates = ["README.md"] + [os.path.join("docs", f) for f in sorted(os.listdir(os.path.join(ROOT, "docs")))
                                  if f.endswith(".md")]
    for page in candidates:
        if os.path.normpath(page) in listed:
            continue
        with open(os.path.join(ROOT, page)) as fh:
            if OPENING.search(fh.read()):
                sys.exit(f"readme_numbers: {page} holds a generated block but is not in PAGES: add it there")
    return texts


def render_block(template, made):
    """A block's text: what its function made, filled into the block's template when it has one."""
    if template is None:
        if not isinstance(made, str):
            raise ValueError("the script gives named values but the block has no template")
        return made
    if not isinstance(made, dict):
        raise ValueError("the block has a template but the script gives the whole text")
    return fill(template, made)


def render(page, text, runner):
    def block(m):
        name, template = m.group(1), m.group(2)
        try:
            body = render_block(template, BLOCKS[name](runner))
        except ValueError as e:
            sys.exit(f"readme_numbers: {page}, block '{name}': {e}")
        opening = f"<!-- generated: {name} -->" if template is None else f"<!-- generated: {name}\n{template}\n-->"
        return f"{opening}\n{body}\n<!-- end: {name} -->"
    return MARK.sub(block, text)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    mode = ap.add_mutually_exclusive_group(required=True)
    mode.add_argument("--write", action="store_true")
    mode.add_argument("--check", action="store_true")
    ap.add_argument("--bin", default=os.path.join(ROOT, "build", "bin", "rlgtherm"))
    a = ap.parse_args()
    old = pages_and_blocks()
    with tempfile.TemporaryDirectory() as tmp:
        runner = Runner(os.path.abspath(a.bin), tmp)
        new = {page: render(page, text, runner) for page, text in old.items()}
    changed = [page for page in PAGES if new[page] != old[page]]
    if a.write:
        for page in changed:
            with open(os.path.join(ROOT, page), "w") as fh:
                fh.write(new[page])
        print(f"updated: {', '.join(changed)}" if changed else "every generated block is already current")
        return 0
    if not changed:
        print("the generated blocks are what the commands print")
        return 0
    for page in changed:
        sys.stdout.writelines(difflib.unified_diff(old[page].splitlines(True), new[page].splitlines(True), page,
                                                   f"{page} (generated)"))
    print(f"\n{', '.join(changed)} differ from what the commands print: "
          "run python3 tools/readme_numbers.py --write --bin build/bin/rlgtherm")
    return 1


if __name__ == "__main__":
    sys.exit(main())
