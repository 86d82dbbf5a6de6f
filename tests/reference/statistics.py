#!/usr/bin/python3
"""statistics.py: how often `rlgtherm diagnose` names a hidden effect at small sizes, on data it
did not make (target: >= 90 % named at 3-6x the 100 s noise over >= 50 drawn cases;
false alarms <= 5 % over >= 20 nulls). A measurement, not a test: nothing here is tuned to pass.

  /usr/bin/python3 tests/reference/statistics.py --rlgtherm build/bin/rlgtherm \
      --n-effects 60 --n-nulls 20 --work /tmp/rlg-stats [--draw-seed 1] [--sample-period 10] \
      [--strength-min 3 --strength-max 6] [--uniform-cases] [--json OUT] [--dry-run]

The draw (reproducible from --draw-seed; numpy PCG64):
  - effect cases: refgen's catalog-effect cases, i.e. every case in refgen.CASES except "none"
    and the "near.*" forms. Included (refgen 1): thermal.missing_mass, thermal.missing_link,
    thermal.power_drift, thermal.radiation, sensor.lag, sensor.offset, bias.temperature_rate,
    bias.gradient, bias.hysteresis, bias.mode_hop. Excluded: none (a null), near.heavy_nominal
    (the heavy-nominal null, used below as a null), near.reversible_hops, near.mass_and_link,
    near.double_lag (near forms, not the catalog's). By default the N cases are balanced: each
    catalog case N // 10 times, the remaining N % 10 cases picked at random without repeats, in
    shuffled order (--uniform-cases: each case drawn independently and uniformly instead). Each
    case gets a random seed (uniform in 1..999999, no (case, seed) twice) and a random strength
    uniform in [3, 6] (multiples of the 100 s noise RMS of what a calibration cannot take up,
    refgen's --strength), rounded to 0.001 so that the work directory names it exactly.
  - nulls: "none" and "near.heavy_nominal" (every heat capacity of the nominal 30 % high)
    alternately, M in all, each with a random seed; no hidden effect (strength 0).
  - every case at --sample-period (default 10 s), written by refgen and run through
    `rlgtherm diagnose data.csv --gyro nominal.toml --json` by survey.run_case, in
    --work DIR/<case>-s<seed>-p<period>-x<strength>/. A case whose diagnose.json exists is not
    run again (an interrupted run resumes); its seconds come from row.json beside it.

Scored per effect case (survey.same_target: a channel counts as its node, pairs in either order;
the main parameter is survey.main_value, hysteresis k_heating - k_cooling):
  (a) named first: accepted[0] is the truth's cause on the truth's target;
  (a1) named as far as the data tell: (a), or accepted[0] is the truth's cause on a target whose
      score the first step puts within 1 point of the truth's target (its ties);
  (a') named first or listed with it: (a), or the truth among the first step's ties within 10
      points or set aside as a stand-in;
  (b) named anywhere: some accepted step is the truth's cause on the truth's target;
  (c) parameter: that step's main parameter within 20 % of the truth's (given (b); and the
      strict rate "named first and within 20 %" over all cases).
  A nonzero exit of diagnose counts as not named. Nulls: a false alarm is anything accepted.
Rates carry a 95 % Wilson score interval (scipy.stats.binomtest(...).proportion_ci).
Prints a markdown table (one row per case) and the summary; --json OUT writes the rows.
"""

import argparse
import collections
import hashlib
import json
import math
import os
import sys
import tempfile
import time

import numpy as np
from scipy.stats import binomtest

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import refgen  # noqa: E402
import survey  # noqa: E402

NULL_CASES = [c for c in ("none", "near.heavy_nominal") if c in refgen.CASES]
EFFECT_CASES = [c for c in refgen.CASES if c != "none" and not c.startswith("near.")]
WITHIN = 0.20        # the parameter within 20 % of the truth's
CONFIDENCE = 0.95
TIE_BAND = 10.0      # rlgtherm's kTieBand (diagnosis/statistics/rank.h): score points within which a tie is listed
# Score points within which two targets of the named cause are as good as one: the score is an
# information-criterion gain, so 1 point is a likelihood ratio of e^0.5 = 1.65 (stricter than
# the 2 points of "substantial support for both" in Burnham & Anderson's AIC rule of thumb).
SAME_BAND = 1.0


# --------------------------------------------------------------------------------------------
# The draw


def draw(n_effects, n_nulls, draw_seed, s_min, s_max, uniform_cases=False):
    """The cases to run: list of dicts {kind, case, seed, strength}, reproducible from draw_seed."""
    rng = np.random.Generator(np.random.PCG64(draw_seed))
    k = len(EFFECT_CASES)
    if uniform_cases:
        cases = [EFFECT_CASES[i] for i in rng.integers(0, k, size=n_effects)]
    else:
        cases = EFFECT_CASES * (n_effects // k)
        cases += [EFFECT_CASES[i] for i in rng.permutation(k)[: n_effects % k]]
        cases = [cases[i] for i in rng.permutation(len(cases))]
    used = set()

    def seed_for(case):
        while True:
            s = int(rng.integers(1, 1000000))
            if (case, s) not in used:
                used.add((case, s))
                return s

    out = []
    for case in cases:
        seed = seed_for(case)
        strength = round(float(rng.uniform(s_min, s_max)), 3)
        out.append({"kind": "effect", "case": case, "seed": seed, "strength": strength})
    for i in range(n_nulls):
        case = NULL_CASES[i % len(NULL_CASES)]
        out.append({"kind": "null", "case": case, "seed": seed_for(case), "strength": 0.0})
    return out


# --------------------------------------------------------------------------------------------
# Running (through survey.run_case) with resume


def case_dir(work, c, period):
    # the directory survey.run_case writes into
    return os.path.join(work, "%s-s%d-p%g-x%g" % (c["case"], c["seed"], period, c["strength"]))


def sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def wait_for_binary(rlg, limit_s=1800):
    """The binary may be rebuilt by others: wait (up to limit_s) until it is there."""
    t0 = time.time()
    while not (os.path.isfile(rlg) and os.access(rlg, os.X_OK)):
        if time.time() - t0 > limit_s:
            raise FileNotFoundError("%s missing for %d s" % (rlg, limit_s))
        print("waiting for %s ..." % rlg, file=sys.stderr, flush=True)
        time.sleep(20)


def thermal_rank(rep):
    """(rank, replicates) of the data's thermal screening score among the thermal null
    bootstrap's replicates (how many replicates it beats), or None where the report has none."""
    t = rep.get("thermal_null_bootstrap") or {}
    data, reps = t.get("data_score"), t.get("replicate_scores") or []
    if data is None or not reps:
        return None
    return sum(1 for x in reps if x is not None and x < data), len(reps)


def load_row(d, c):
    """A finished case from its directory (diagnose.json present), or None."""
    if not os.path.exists(os.path.join(d, "diagnose.json")):
        return None
    truth = json.load(open(os.path.join(d, "truth.json")))
    rep = json.load(open(os.path.join(d, "diagnose.json")))
    meta = {}
    if os.path.exists(os.path.join(d, "row.json")):
        meta = json.load(open(os.path.join(d, "row.json")))
    return {"case": c["case"], "seed": c["seed"], "strength": c["strength"], "kind": c["kind"],
            "truth": truth, "status": 0, "seconds": meta.get("seconds", float("nan")),
            "gen_seconds": meta.get("gen_seconds", float("nan")),
            "rlgtherm_sha256": meta.get("rlgtherm_sha256"), "resumed": True,
            "accepted": survey.accepted_of(rep),
            "unexplained": rep.get("unexplained") or [],
            "thermal_rank": thermal_rank(rep),
            "prior_conflicts": rep.get("calibration", {}).get("prior_conflicts", [])}


def run_one(rlg, c, period, work):
    d = case_dir(work, c, period)
    row = load_row(d, c)
    if row is not None:
        return row
    wait_for_binary(rlg)
    binsum = sha256(rlg)
    t0 = time.time()
    try:
        row = survey.run_case(rlg, c["case"], c["seed"], period, c["strength"], work)
    except FileNotFoundError:       # the binary vanished between the check and the run
        wait_for_binary(rlg)
        t0 = time.time()
        row = survey.run_case(rlg, c["case"], c["seed"], period, c["strength"], work)
    total = time.time() - t0
    row.update({"kind": c["kind"], "strength": c["strength"], "gen_seconds": total - row["seconds"],
                "rlgtherm_sha256": binsum, "resumed": False})
    if row["status"] == 0:
        rep = json.load(open(os.path.join(d, "diagnose.json")))
        row["unexplained"] = rep.get("unexplained") or []
        row["thermal_rank"] = thermal_rank(rep)
    with open(os.path.join(d, "row.json"), "w") as f:
        json.dump({"seconds": row["seconds"], "gen_seconds": row["gen_seconds"],
                   "status": row["status"], "error": row.get("error"),
                   "rlgtherm_sha256": binsum}, f, indent=1)
    return row


# --------------------------------------------------------------------------------------------
# Scoring


def score(row):
    """Adds row["score"]: for effects named_first, named_any, step, ratio, param_ok, strict;
    for nulls false_alarm. And row["verdict"], a short word for the table."""
    t = row["truth"]
    s = {}
    if row["status"] != 0:
        s.update(named_first=False, named_same=False, named_tied=False, named_set_aside=False, named_any=False, step=None,
                 ratio=None, param_ok=False, strict=False, false_alarm=None)
        row["score"] = s
        row["verdict"] = "exit %d" % row["status"]
        return row
    acc = row["accepted"]
    if row["kind"] == "null":
        s["false_alarm"] = bool(acc)
        row["score"] = s
        row["verdict"] = "FALSE ALARM" if acc else "clean"
        return row
    eff = t["effects"][0]
    name, target = eff["name"], eff["target"]
    want = survey.main_value(name, eff["parameters"])
    s["named_first"] = bool(acc) and acc[0]["cause"] == name and \
        survey.same_target(name, acc[0]["target"], target)
    # Named first or listed with it: the first step's ties within the band (the report's
    # "ambiguous:" note: the data cannot tell them apart) or its stand-ins set aside (the data
    # prefer them at a size outside the catalog's range).
    first_ties = acc[0].get("ties", []) if acc else []
    listed = [x for x in first_ties if x["cause"] == name and survey.same_target(name, x["target"], target)]
    s["named_tied"] = s["named_first"] or any(x["ambiguous"] for x in listed)
    # Named as far as the data tell: the cause first, on the truth's target or on one the first
    # step scores within SAME_BAND of it (separability.py: a power drift's cathode, anode and
    # block, a gradient's far ends).
    s["named_same"] = s["named_first"] or (bool(acc) and acc[0]["cause"] == name and
                                           any(abs(x["score_difference"]) < SAME_BAND for x in listed))
    s["named_set_aside"] = not s["named_tied"] and any(not x["plausible"] for x in listed)
    s["step"], s["ratio"] = None, None
    for k, a in enumerate(acc, start=1):
        if a["cause"] == name and survey.same_target(name, a["target"], target):
            got = survey.main_value(a["cause"], a["parameters"])
            s["step"] = k
            s["ratio"] = got / want if (got is not None and want) else None
            break
    s["named_any"] = s["step"] is not None
    s["param_ok"] = s["ratio"] is not None and abs(s["ratio"] - 1.0) <= WITHIN
    s["strict"] = s["named_first"] and s["param_ok"]
    # the cause named on another target, if any (for the table)
    s["wrong_target"] = next((a["target"] for a in acc if a["cause"] == name
                              and not survey.same_target(name, a["target"], target)), None)
    if s["named_first"]:
        v = "named" if s["param_ok"] else "named, param x%.2f" % s["ratio"] if s["ratio"] else \
            "named, param ?"
    elif s["named_tied"]:
        v = "tied with %s %s" % (acc[0]["cause"], acc[0]["target"])
    elif s["named_set_aside"]:
        v = "set aside as a stand-in for %s %s" % (acc[0]["cause"], acc[0]["target"])
    elif s["named_any"]:
        v = "named at step %d" % s["step"] + ("" if s["param_ok"] else
                                              (", param x%.2f" % s["ratio"] if s["ratio"] else ""))
    elif acc and acc[0]["cause"] == name:
        v = "wrong target (%s)" % acc[0]["target"]
    elif s["wrong_target"] is not None:
        v = "wrong cause; the cause later on %s" % s["wrong_target"]
    elif acc:
        v = "wrong cause"
    else:
        v = "missed (none)"
    row["score"] = s
    row["verdict"] = v
    return row


def first_label(row):
    if row["status"] != 0:
        return "exit %d: %s" % (row["status"], row.get("error", ""))
    if not row["accepted"]:
        return "none"
    a = row["accepted"][0]
    s = survey.short(a["cause"], a["target"], survey.main_value(a["cause"], a["parameters"]))
    if a.get("plausible") is False:
        s += " [implausible]"
    return s


def ci(k, n):
    if n == 0:
        return (float("nan"), float("nan"))
    c = binomtest(k, n).proportion_ci(confidence_level=CONFIDENCE, method="wilson")
    return (c.low, c.high)


def rate(k, n):
    if n == 0:
        return "-"
    lo, hi = ci(k, n)
    return "%d/%d = %.0f %% [%.0f, %.0f]" % (k, n, 100.0 * k / n, 100 * lo, 100 * hi)


def table(rows):
    out = ["| # | effect | target | truth param | strength | seed | first accepted | verdict |"
           " all accepted |",
           "|---|---|---|---|---|---|---|---|---|"]
    for i, r in enumerate(rows, start=1):
        t = r["truth"]
        v = survey.main_value(t["effect"], t["parameters"])
        every = "; ".join("%s %s" % (a["cause"], a["target"] or "")
                          for a in r.get("accepted", [])) or "-"
        out.append("| %d | %s | %s | %s | %s | %d | %s | %s | %s |"
                   % (i, r["case"], t["target"] or "", "%.3g" % v if v is not None else "",
                      "%.3f" % r["strength"] if r["kind"] == "effect" else "-", r["seed"],
                      first_label(r), r["verdict"], every))
    return "\n".join(out)


def summary(rows):
    eff = [r for r in rows if r["kind"] == "effect"]
    nul = [r for r in rows if r["kind"] == "null"]
    L = ["95 %% intervals: Wilson score. Parameter bound: within %d %% of the truth's main "
         "parameter." % (100 * WITHIN), ""]
    L += ["(a1) counts (a) and the cases whose cause is named first on a target the first step scores within %g"
          " point of the truth's (a likelihood ratio below 1.65: the data do not tell the two apart)." % SAME_BAND,
          "(a') counts (a) and the cases whose truth the first step lists among its ties: within %g score points"
          " on the fit or the held-out data (the report's \"ambiguous:\" note), or a stand-in the data preferred but"
          " the catalog's range set aside (its \"set aside:\" note)." % TIE_BAND, ""]
    L += ["| effect | n | (a) named first | (a1) named first, target as far as the data tell"
          " | (a') named first or listed with it | (b) named anywhere"
          " | (c) param within 20 %, given (b) | named first and param within 20 % |",
          "|---|---|---|---|---|---|---|---|"]
    groups = [(c, [r for r in eff if r["case"] == c]) for c in EFFECT_CASES]
    for name, g in groups + [("**all effects**", eff)]:
        if not g:
            continue
        n = len(g)
        a = sum(r["score"]["named_first"] for r in g)
        b = sum(r["score"]["named_any"] for r in g)
        c = sum(r["score"]["param_ok"] for r in g)
        st = sum(r["score"]["strict"] for r in g)
        t = sum(r["score"]["named_tied"] or r["score"]["named_set_aside"] for r in g)
        a1 = sum(r["score"]["named_same"] for r in g)
        L.append("| %s | %d | %s | %s | %s | %s | %s | %s |" % (name, n, rate(a, n), rate(a1, n), rate(t, n),
                                                               rate(b, n), rate(c, b), rate(st, n)))
    L.append("")
    L += ["| null | n | false alarms (anything accepted) | what was accepted first |",
          "|---|---|---|---|"]
    for name, g in [(c, [r for r in nul if r["case"] == c]) for c in NULL_CASES] + \
            [("**all nulls**", nul)]:
        if not g:
            continue
        fa = sum(bool(r["score"]["false_alarm"]) for r in g)
        cnt = collections.Counter(first_label(r) if r["status"] == 0 else "exit %d" % r["status"]
                                  for r in g if r["status"] != 0 or r["accepted"])
        what = "; ".join("%s ×%d" % (k, v) for k, v in cnt.most_common()) or "-"
        L.append("| %s | %d | %s | %s |" % (name, len(g), rate(fa, len(g)), what))
    L.append("")
    L.append("What each effect is taken for when not named first (accepted[0], cause and target;"
             " count):")
    L.append("")
    for c, g in groups:
        wrong = collections.Counter()
        for r in g:
            if r["score"]["named_first"]:
                continue
            if r["status"] != 0:
                wrong["exit %d" % r["status"]] += 1
            elif not r["accepted"]:
                wrong["none"] += 1
            else:
                a = r["accepted"][0]
                wrong["%s %s" % (a["cause"], a["target"] or "")] += 1
        if wrong:
            L.append("- %s: %s" % (c, "; ".join("%s ×%d" % (k, v) for k, v in wrong.most_common())))
    L.append("")
    secs = [r["seconds"] for r in rows if not math.isnan(r.get("seconds", float("nan")))]
    gens = [r["gen_seconds"] for r in rows if not math.isnan(r.get("gen_seconds", float("nan")))]
    bad = [r for r in rows if r["status"] != 0]
    impl = sum(1 for r in rows if r["status"] == 0 for a in r["accepted"] if a.get("plausible") is False)
    unexp = sum(1 for r in nul if r["status"] == 0 and r.get("unexplained"))
    L.append("diagnose wall time per case: mean %.1f s, median %.1f s, max %.1f s over %d timed "
             "runs (refgen's generation: mean %.1f s more)"
             % (np.mean(secs) if secs else float("nan"), np.median(secs) if secs else float("nan"),
                max(secs) if secs else float("nan"), len(secs),
                np.mean(gens) if gens else float("nan")))
    L.append("nonzero exit statuses: %d%s" % (len(bad), "".join(
        "; %s seed %d exit %d (%s)" % (r["case"], r["seed"], r["status"], r.get("error", ""))
        for r in bad)))
    L.append("accepted steps marked \"plausible\": false: %d; nulls with a non-empty `unexplained`:"
             " %d of %d" % (impl, unexp, len(nul)))
    ranks = [r["thermal_rank"] for r in nul if r["status"] == 0 and r.get("thermal_rank")]
    if ranks:
        # An honest bootstrap puts a null's rank uniformly on 0..R: beyond all R replicates
        # about once in R + 1 nulls, in the lower half about half the time.
        R = ranks[0][1]
        L.append("thermal null bootstrap on the nulls: the data's screening score beats all %d replicates on %d of %d "
                 "(uniform ranks: about %.1f), fewer than half of them on %d of %d (about %.0f)"
                 % (R, sum(1 for k, n in ranks if k == n), len(ranks), len(ranks) / (R + 1.0),
                    sum(1 for k, n in ranks if k < n / 2.0), len(ranks), len(ranks) / 2.0))
    shas = sorted({r.get("rlgtherm_sha256") for r in rows if r.get("rlgtherm_sha256")})
    L.append("rlgtherm binary sha256: %s" % (", ".join(s[:16] for s in shas) or "not recorded")
             + (" (MORE THAN ONE BINARY: results mix versions)" if len(shas) > 1 else ""))
    return "\n".join(L)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rlgtherm", required=True)
    ap.add_argument("--n-effects", type=int, default=60)
    ap.add_argument("--n-nulls", type=int, default=20)
    ap.add_argument("--draw-seed", type=int, default=1)
    ap.add_argument("--sample-period", type=float, default=10.0)
    ap.add_argument("--strength-min", type=float, default=3.0)
    ap.add_argument("--strength-max", type=float, default=6.0)
    ap.add_argument("--uniform-cases", action="store_true",
                    help="draw each effect case independently (default: balanced over the catalog)")
    ap.add_argument("--work", default=None, help="case directories; rerun to resume")
    ap.add_argument("--json", default=None, help="also write the rows as JSON")
    ap.add_argument("--dry-run", action="store_true", help="print the draw and stop")
    a = ap.parse_args()
    cases = draw(a.n_effects, a.n_nulls, a.draw_seed, a.strength_min, a.strength_max,
                 a.uniform_cases)
    if a.dry_run:
        for c in cases:
            print("%-6s %-24s seed %6d strength %.3f" % (c["kind"], c["case"], c["seed"],
                                                         c["strength"]))
        return 0
    rlg = os.path.abspath(a.rlgtherm)
    work = a.work or tempfile.mkdtemp(prefix="rlg-stats-")
    os.makedirs(work, exist_ok=True)
    rows = []
    t_start = time.time()
    for i, c in enumerate(cases, start=1):
        r = score(run_one(rlg, c, a.sample_period, work))
        rows.append(r)
        print("[%d/%d %.0f s] %s seed %d x%.3f: %s -> %s%s"
              % (i, len(cases), time.time() - t_start, c["case"], c["seed"], c["strength"],
                 first_label(r), r["verdict"], " (resumed)" if r.get("resumed") else
                 " (%.1f s)" % r["seconds"]), file=sys.stderr, flush=True)
    print("# rlgtherm diagnose on drawn refgen cases\n")
    print("%d effect cases (strength uniform in [%g, %g], %s), %d nulls; sample period %g s; "
          "draw seed %d; work %s\n"
          % (a.n_effects, a.strength_min, a.strength_max,
             "cases drawn uniformly" if a.uniform_cases else "balanced over the catalog",
             a.n_nulls, a.sample_period, a.draw_seed, work))
    print("## Summary\n")
    print(summary(rows))
    print("\n## Cases\n")
    print(table(rows))
    if a.json:
        with open(a.json, "w") as f:
            json.dump([{k: v for k, v in r.items() if k != "truth"} | {
                "truth_effects": r["truth"]["effects"]} for r in rows], f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main())
