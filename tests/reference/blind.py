#!/usr/bin/env python3
"""blind.py --rlgtherm BIN --work DIR [--period S] [--seeds 1,2]: blind tests of `rlgtherm
diagnose` on data it did not make.

refgen (written without reading sim/) generates each case at a clear size (10 times the 100 s
noise in the part a calibration cannot take up; 10 s samples and seeds 1 and 2 by default,
CTest also runs 1 s samples on seed 2 and 60 s samples on seed 1), with the nominal off within
its stated prior; `diagnose` sees only data.csv and nominal.toml, and its JSON is
compared with truth.json afterwards (survey.run_case). Asserted, per case and seed:

  - nulls (`none`, and `near.heavy_nominal`, the nominal with every heat capacity 30 % high):
    nothing accepted and nothing reported `unexplained` (at 1 s, before each run's start was a
    nuisance, the block's start error was); for the heavy nominal the calibration says its knobs are jointly in
    conflict with their prior (calibration.joint_shift.conflict). Also the heavy nominal at
    seed 124461 (HARD_NULLS), whose fit from the nominal ends in a wrong minimum (the cathode's
    capacity +13 prior sd, 5x the noise on the block; a missing mass was then accepted): the
    calibration must restart from a common heat-capacity scale below 1 and accept nothing;
  - one hidden effect: the first accepted step is the truth's cause (or, for a near form, the
    catalog cause it is named as: NAMED_AS) on the truth's target (a channel counts as its node,
    survey.same_target) and its main parameter is within 20 % of the truth's (the bound
    at clear sizes).

Cases refgen has that are not asserted here, and why (the README, "Diagnosis: data it did not
make", says what each is named as; survey.py prints the table). bias.temperature_rate (STAND_IN):
refgen sizes it at 2.2 deg/h per degC/min, outside the catalog's plausible range of 1, so
gradients are named; asserted is that the first step lists the truth (cause and target) among
its ties as a stand-in (plausible false). Asserted in a weaker form (TIED): a power
drift of the cathode and a gradient block-housing, whose targets the data cannot tell apart
(the heated legs share one source; the housing is the far end of every gradient): the first
accepted step is the truth's cause with its parameter within 20 %, and the truth's target is
that step's or one of its ambiguous ties (accepted[0].ties, the "ambiguous:" note).
Also near.mass_and_link (BOTH): each of its two effects accepted at some step, on its target,
within 20 %. Known misses (KNOWN_MISSES, said in the README) are strict expected failures: they
must fail with the assertions listed for them and no others, and a known miss that passes, or
fails otherwise (a diagnose that does not run, another misnaming), fails the test.
In every case, a thermal step tied in score that another step may follow was compared one step
ahead (check_lookahead), and the first such step of the run leaves the record the lookahead
promises (check_lookahead_record). Exit 1 listing every failed assertion.
"""

import argparse
import json
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import survey  # noqa: E402

SINGLE = ["thermal.missing_mass", "thermal.missing_link", "thermal.radiation", "sensor.lag", "sensor.offset", "bias.hysteresis",
          "bias.mode_hop", "near.reversible_hops", "near.double_lag"]
# A second lag on T2, whose 30 s lag the nominal already has, is sensor.lag T2 with the second
# stage's time constant (sensor.lag on a lagged channel adds a stage in series).
# A form near a catalog effect is named as that effect. Reversible hops, a
# staircase of absolute block temperature 13 degC apart, are a mode hop without hysteresis
# (range 0.5) at a power-on phase set by the absolute temperature (centre_C), whose spacing the
# search finds: asserted below within 20 %, and flagged implausible, as 13 degC lies below
# docs/physics.md's 15-70 K per mode (a block expanding faster than Zerodur): a stand-in, reported so.
NAMED_AS = {"near.reversible_hops": "bias.mode_hop"}
TIED = ["thermal.power_drift", "bias.gradient"]
BOTH = ["near.mass_and_link"]
# (case, seed, period): what diagnose gets wrong here, and why.
KNOWN_MISSES = {
    # (case, seed, period): (what the README says, the failed assertions it must give: each a
    # regular expression; every failure must match one and each must match a failure, so a miss
    # that changes its form, or a diagnose that fails to run, fails the test).
    # At 60 s a sample carries a 1 s reading's noise and a 120 s score block holds two: the
    # link is named, then a block-cathode mass of 10 J/K.
    ("near.mass_and_link", 1, 60.0): ("the mass named block-cathode at 10 J/K",
                                      [r"thermal\.missing_mass accepted at step \d on (block-cathode|cathode-block),"]),
}
STAND_IN = ["bias.temperature_rate"]
NULLS = ["none", "near.heavy_nominal"]
SEEDS = [1, 2]
# Nulls at seeds whose calibration from the nominal ends in a wrong minimum (Engine::Calibrate).
HARD_NULLS = [("near.heavy_nominal", 124461)]
WITHIN = 0.20  # at clear sizes, the parameter within 20 % of the truth's


def diagnose_json(work, case, seed, period):
    d = os.path.join(work, "%s-s%d-p%g-x10" % (case, seed, period))
    return json.load(open(os.path.join(d, "diagnose.json")))


def check_tied(first, effect, failures, label):
    """The first accepted step is the truth's cause within 20 %, on the truth's target or with
    it among the step's ambiguous ties (within the band on the fit or the held-out data)."""
    if first["cause"] != effect["name"]:
        failures.append("%s: first accepted %s, truth %s" % (label, first["cause"], effect["name"]))
        return
    targets = [first["target"]] + [t["target"] for t in first.get("ties", [])
                                   if t["cause"] == effect["name"] and t["ambiguous"]]
    if not any(survey.same_target(effect["name"], t, effect["target"]) for t in targets):
        failures.append("%s: truth's target %s neither accepted nor tied (%s)" % (label, effect["target"], targets))
    want = survey.main_value(effect["name"], effect["parameters"])
    got = survey.main_value(first["cause"], first["parameters"])
    if got is None or abs(got / want - 1.0) > WITHIN:
        failures.append("%s: %s parameter %s against the truth's %.4g" % (label, first["cause"], got, want))


def check_effect(row, effect, failures, label):
    for k, a in enumerate(row["accepted"], start=1):
        if a["cause"] != NAMED_AS.get(effect["name"], effect["name"]):
            continue
        if effect["name"] == "near.reversible_hops":
            p, t = a["parameters"], effect["parameters"]
            if abs(p["mode_spacing_C"] / t["spacing_C"] - 1.0) > WITHIN:
                failures.append("%s: mode spacing %.4g against the truth's %.4g" % (label, p["mode_spacing_C"], t["spacing_C"]))
            if "centre_C" not in p or p["range_modes"] > 0.55:
                failures.append("%s: not reversible hops at an absolute phase: %s" % (label, p))
            if a.get("plausible", True):
                failures.append("%s: a 13 degC spacing is not flagged implausible" % label)
        if not survey.same_target(effect["name"], a["target"], effect["target"]):
            failures.append("%s: %s accepted at step %d on %s, truth on %s"
                            % (label, a["cause"], k, a["target"], effect["target"]))
            return
        want = survey.main_value(effect["name"], effect["parameters"])
        got = survey.main_value(a["cause"], a["parameters"])
        if got is None or abs(got / want - 1.0) > WITHIN:
            failures.append("%s: %s parameter %s against the truth's %.4g (more than %d %% off)"
                            % (label, a["cause"], got, want, 100 * WITHIN))
        return
    failures.append("%s: %s never accepted (accepted: %s)"
                    % (label, effect["name"], [a["cause"] + " " + (a["target"] or "") for a in row["accepted"]]))


MAX_STEPS = 3  # diagnose's default --max-steps (survey.run_case gives none), with lookahead 2


def check_lookahead(row, failures, label):
    """Every accepted thermal step but the last one allowed that ties a plausible thermal
    candidate in score (within the 10-point band, not an exact twin) was compared one step
    ahead (docs/diagnosis.md, "The method": looking one step ahead): its note says so. (A tie's
    plausibility is that of its ranked fit, as diagnose judges it; a tie outside the catalog's
    range is compared only after a stand-in leader, which this does not ask.)"""
    for k, a in enumerate(row["accepted"][:MAX_STEPS - 1], start=1):
        if a.get("kind") != "thermal":
            continue
        tied = [t for t in a.get("ties", []) if t["ambiguous"] and 1e-6 <= abs(t["score_difference"]) < 10.0
                and t["plausible"]]  # a thermal step's ties are thermal; 1e-6: diagnose's tie_score
        if tied and not any(n.startswith("looked one step ahead") for n in a.get("notes", [])):
            failures.append("%s: step %d ties %s %s in score but was not compared one step ahead"
                            % (label, k, tied[0]["cause"], tied[0]["target"]))


LOOKED = re.compile(r"^looked one step ahead \(a tie in score\): (\S+) (\S+) \(([-+0-9.e]+)\)")


def without_lookahead_notes(report):
    """The report with every step's `looked one step ahead` note taken out."""
    out = json.loads(json.dumps(report))
    for step in out.get("accepted", []):
        step["notes"] = [n for n in step.get("notes", []) if not n.startswith("looked one step ahead")]
    return out


def check_lookahead_record(a, rows, failures):
    """What looking ahead leaves in the record. Where a rival was taken, its ties hold the
    passed-over leader with a score difference above 0 (every such step of the run). Where the
    leader was kept, the whole report is the greedy one's (`--lookahead 1`, diagnosed again, on
    the first case of the run where every compared step kept it) but for the note: the lookahead changes which cause is taken
    and nothing else."""
    rerun = False
    for row in rows:
        if row["status"] != 0:
            continue
        for k, step in enumerate(row["accepted"], start=1):
            notes = [LOOKED.match(n) for n in step["notes"]]
            m = next((x for x in notes if x), None)
            if not m:
                continue
            label = "%s seed %d at %g s, step %d" % (row["case"], row["seed"], row["period"], k)
            leader = (m.group(1), m.group(2))
            if (step["cause"], step["target"]) != leader:
                if not any((t["cause"], t["target"]) == leader and t["score_difference"] > 0 for t in step["ties"]):
                    failures.append("%s: a rival was taken one step ahead, but its ties do not hold the leader %s %s "
                                    "above it" % (label, leader[0], leader[1]))
                continue
            # Greedy's report only where no step of the case took a rival.
            kept = all((x["cause"], x["target"]) == (mm.group(1), mm.group(2))
                       for x in row["accepted"] for mm in map(LOOKED.match, x["notes"]) if mm)
            if rerun or not kept:
                continue
            rerun = True
            d = os.path.join(a.work, "%s-s%d-p%g-x10" % (row["case"], row["seed"], row["period"]))
            p = subprocess.run([a.rlgtherm, "diagnose", os.path.join(d, "data.csv"), "--gyro",
                                os.path.join(d, "nominal.toml"), "--json", "--lookahead", "1"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
            if p.returncode != 0:
                failures.append("%s: diagnose --lookahead 1 exit %d" % (label, p.returncode))
            elif without_lookahead_notes(json.loads(p.stdout)) != without_lookahead_notes(diagnose_json(
                    a.work, row["case"], row["seed"], row["period"])):
                failures.append("%s: the leader was kept one step ahead, but the report differs from "
                                "--lookahead 1's beyond the note" % label)
            else:
                print("lookahead record: %s kept its leader; the report is --lookahead 1's but for the note" % label)


def check_case(a, case, seed, row, label):
    """The failed assertions of one case (see the module's doc)."""
    failures = []
    if row["status"] != 0:
        return ["%s: diagnose exit %d: %s" % (label, row["status"], row.get("error", ""))]
    check_lookahead(row, failures, label)
    effects = row["truth"]["effects"]
    if case in NULLS:
        if row["accepted"]:
            failures.append("%s: false alarm, accepted %s" % (label, [x["cause"] for x in row["accepted"]]))
        report = diagnose_json(a.work, case, seed, a.period)
        calibration = report["calibration"]
        if report.get("unexplained"):
            failures.append("%s: a null's final model reported as missing the data: %s" % (label, [
                "%s %s" % (u.get("channel"), u.get("run")) for u in report["unexplained"]]))
        if case == "near.heavy_nominal" and not calibration["joint_shift"]["conflict"]:
            failures.append("%s: the heavy nominal's calibration is not flagged as a joint conflict" % label)
        if (case, seed) in HARD_NULLS and not calibration["start_capacity_scale"] < 1.0:
            failures.append("%s: the calibration did not restart from lighter heat capacities" % label)
    elif case in TIED:
        if not row["accepted"]:
            failures.append("%s: nothing accepted, truth %s" % (label, effects[0]["name"]))
        else:
            check_tied(row["accepted"][0], effects[0], failures, label)
    elif case in STAND_IN:
        e = effects[0]
        listed = [t for x in row["accepted"][:1] for t in x.get("ties", [])
                  if t["cause"] == e["name"] and survey.same_target(e["name"], t["target"], e["target"])
                  and not t["plausible"]]
        if not listed:
            failures.append("%s: %s %s not listed as a stand-in in the first step's ties"
                            % (label, e["name"], e["target"]))
    elif case in BOTH:
        for e in effects:
            check_effect(row, e, failures, "%s (%s)" % (label, e["name"]))
    else:
        first = row["accepted"][:1]
        if not first or first[0]["cause"] != NAMED_AS.get(effects[0]["name"], effects[0]["name"]):
            failures.append("%s: first accepted %s, truth %s"
                            % (label, first[0]["cause"] if first else "none", effects[0]["name"]))
        else:
            check_effect({"accepted": first}, effects[0], failures, label)
    return failures


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--rlgtherm", required=True)
    ap.add_argument("--work", required=True)
    ap.add_argument("--period", type=float, default=10.0, help="sample period (s) of refgen's data")
    ap.add_argument("--seeds", default=",".join(str(s) for s in SEEDS))
    a = ap.parse_args()
    seeds = [int(s) for s in a.seeds.split(",")]
    hard = [(c, s) for c, s in HARD_NULLS if a.period == 10.0]  # found on 10 s data
    failures, rows = [], []
    for case, seed in [(c, s) for c in NULLS + SINGLE + TIED + BOTH + STAND_IN for s in seeds] + hard:
        row = survey.run_case(a.rlgtherm, case, seed, a.period, 10.0, a.work)
        rows.append(row)
        label = "%s seed %d at %g s" % (case, seed, a.period)
        found = check_case(a, case, seed, row, label)
        known = KNOWN_MISSES.get((case, seed, a.period))
        if not known:
            failures += found
            continue
        said, patterns = known
        if not found:
            failures.append("%s: a known miss (%s) now passes: update KNOWN_MISSES and the README" % (label, said))
        elif (all(any(re.search(p, f) for p in patterns) for f in found)
              and all(any(re.search(p, f) for f in found) for p in patterns)):
            print("known miss (README): %s: %s; %s" % (label, said, "; ".join(found)))
        else:
            failures.append("%s: not the known miss (%s) but: %s" % (label, said, "; ".join(found)))
    check_lookahead_record(a, rows, failures)
    print(survey.table(rows))
    for f in failures:
        print("FAILED " + f)
    print("%d cases, %d failed assertions" % (len(rows), len(failures)))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
