#!/usr/bin/python3
"""separability.py: could any method have named the target of statistics.py's misses?

For each effect case of a statistics.py --json file (by default those not named first on the
truth's target), refgen writes the same draw (case, seed, period, strength, nominal) without
noise, and `rlgtherm diagnose` scores the truth's cause on every target there. It prints

  share    = (S_truth - S_other) / S_truth, the scores of the truth's target and of the best
             other target of the same cause on the noise-free data: the part of the effect's
             signal that the other target cannot reproduce (diagnose's information gain is the
             drop in the sum of squares over the baseline's; the penalty, the same for both, is
             left in S_truth: a few points in thousands for thermal causes, 5 in 184 for bias);
  expected = share x the noisy case's score of the truth [est]: the separation E the noisy data
             hold on average, in score points. Were the score a chi-square difference, the
             score difference of the two targets would have sd ~2 sqrt(E) under the noise, and a
             namer that treats the targets alike would pick the truth's with probability at most
             Phi(sqrt(E) / 2): 69 % at E = 1, a coin flip at E = 0.01. The thermal score is
             close to that (its variance is the channel's, mostly noise); the bias score is not:
             it divides by the baseline's residual variance, the effect's own signal included,
             and saturates on noise-free data, so a bias case's E is a lower estimate. (On the
             six hysteresis draws of statistics-baseline.md the noisy block-minus-cathode score
             differences have mean 0.31, near their E of 0.36-0.48, but sd 0.60, half a
             chi-square difference's: mean / sd = d / 2 puts d^2 near 1, and the chance of the
             right target near Phi(1/2) = 69 %, not Phi(0.3) = 62 %.)

A measurement with refgen's data (the blind tests' misses), not a test:

  /usr/bin/python3 tests/reference/separability.py --rlgtherm build/bin/rlgtherm \\
      --stats /tmp/rlg-stats.json --noisy-work /tmp/rlg-stats --work /tmp/rlg-sep [--all]

--noisy-work is statistics.py's --work (each case's diagnose.json there gives the noisy score).
"""

import argparse
import json
import math
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import refgen  # noqa: E402
import survey  # noqa: E402


def target_scores(rep, cause):
    """{target: score} of `cause` among the report's candidates, screened ones included (the best
    of each target)."""
    out = {}
    for c in rep["candidates"]:
        if c["cause"] == cause and c["kind"] != "thermal (no effect)":
            out[c["target"]] = max(out.get(c["target"], c["score"]), c["score"])
    return out


def truth_key(scores, truth, cause):
    for k in scores:
        if survey.same_target(cause, k, truth):
            return k
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rlgtherm", required=True)
    ap.add_argument("--stats", required=True, help="statistics.py --json output")
    ap.add_argument("--noisy-work", required=True, help="statistics.py --work directory")
    ap.add_argument("--work", required=True, help="where the noise-free cases are written")
    ap.add_argument("--all", action="store_true", help="every effect case, not only the misses")
    a = ap.parse_args()
    rows = json.load(open(a.stats))
    done = []  # (expected separation, named first) of each case printed
    print("| case | seed | x noise | truth target | best other | share | noisy score | expected | named first |")
    print("|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        if r.get("kind") != "effect" or (not a.all and r["score"]["named_first"]):
            continue
        t = r["truth_effects"][0]
        cause = t["name"]
        name = "%s-s%d-p%g-x%g" % (r["case"], r["seed"], r["period"], r["strength"])
        d = os.path.join(a.work, name)
        out = os.path.join(d, "diagnose.json")
        if not os.path.exists(out):  # a case already diagnosed is not run again
            refgen.write_case(refgen.generate(r["case"], r["seed"], r["period"], r["strength"], noise=False), d)
            p = subprocess.run([a.rlgtherm, "diagnose", os.path.join(d, "data.csv"), "--gyro",
                                os.path.join(d, "nominal.toml"), "--json"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            if p.returncode != 0:
                print("| %s | %d | %g | diagnose exit %d | | | | | |" % (r["case"], r["seed"], r["strength"], p.returncode))
                continue
            with open(out + ".part", "w") as f:  # a run killed here leaves no half report
                f.write(p.stdout)
            os.replace(out + ".part", out)
        clean = target_scores(json.load(open(out)), cause)
        tk = truth_key(clean, t["target"], cause)
        if tk is None:
            print("| %s | %d | %g | %s not a candidate | | | | | |" % (r["case"], r["seed"], r["strength"], t["target"]))
            continue
        # Other targets: not the truth's under another name (a channel is its node).
        other = max(((s, k) for k, s in clean.items() if not survey.same_target(cause, k, t["target"])),
                    default=(None, None))
        named = r["score"]["named_first"]
        if clean[tk] <= 0.0:
            print("| %s | %d | %g | %s scores %.1f without noise | | | | | %s |" % (
                r["case"], r["seed"], r["strength"], tk, clean[tk], "yes" if named else "no"))
            continue
        single = other[0] is None  # one target (a mode hop acts on the block alone): nothing to confuse
        share = None if single else (clean[tk] - other[0]) / clean[tk]
        noisy = None
        nj = os.path.join(a.noisy_work, name, "diagnose.json")
        if os.path.exists(nj):
            ns = target_scores(json.load(open(nj)), cause)
            nk = truth_key(ns, t["target"], cause)
            noisy = ns.get(nk) if nk else None
        expected = share * noisy if share is not None and noisy is not None else None
        print("| %s | %d | %g | %s | %s | %s | %s | %s | %s |" % (
            r["case"], r["seed"], r["strength"], tk, other[1] or "none",
            "one target" if single else "%.2g" % share, "%.1f" % noisy if noisy is not None else "",
            "%.2g" % expected if expected is not None else "", "yes" if named else "no"), flush=True)
        if single:
            done.append((None, t["name"], named))
        elif expected is not None:
            done.append((expected, t["name"], named))
        else:
            print("|   (no noisy score in %s: left out of the summary) |" % nj)
    summary(done)


def summary(done):
    """Counts over the cases printed: separable (expected >= 1 point) or not, named first in each,
    and the two-way bound sum of Phi(sqrt(expected) / 2): the chance that the truth's target
    out-scores the best other when their score difference is normal with mean `expected` and
    sd 2 sqrt(expected), a noncentral chi-square's. Optimistic for a namer that treats the
    targets alike: it ignores a third target as close, the nominal's errors and the other
    causes. The bias score is not on that scale (InformationGain divides by the baseline's
    residual variance, the effect's own signal included, and by its autocorrelation), so a
    bias case's E is a lower estimate: the bound is also printed with the bias E times 50."""
    if not done:
        return

    def phi(x):  # the standard normal CDF
        return 0.5 * (1.0 + math.erf(x / math.sqrt(2.0)))

    def bound(bias_scale):  # targets an ideal namer gets first, each bias E times bias_scale
        b = 0.0
        for e, cause, _ in done:
            scale = bias_scale if cause.startswith("bias.") else 1.0
            b += 1.0 if e is None else phi(math.sqrt(max(scale * e, 0.0)) / 2.0)
        return b

    sep = [n for e, _, n in done if e is None or e >= 1.0]
    insep = [n for e, _, n in done if e is not None and e < 1.0]
    n = len(done)
    print()
    print("%d cases; target separable (expected >= 1 point, or one target): %d, named first in %d; "
          "not separable: %d, named first in %d" % (n, len(sep), sum(sep), len(insep), sum(insep)))
    print("two-way bound on naming the target first: %.1f of %d (%.0f %%); with every bias E "
          "times 50: %.1f (%.0f %%)" % (bound(1.0), n, 100.0 * bound(1.0) / n, bound(50.0), 100.0 * bound(50.0) / n))


if __name__ == "__main__":
    main()
