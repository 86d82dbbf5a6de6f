#!/usr/bin/env python3
"""validate_peak.py RLGTHERM SUITE.toml: every Table 2 row of `validate --json` carries
peak_abs_100s_after_dph (the largest |100 s mean| of the compensated bias), a finite number >= 0,
and has a "peak 100s" check whose value is that number (so the JUnit file, written from the
same checks, carries it too: validate_junit.py)."""
import json
import math
import subprocess
import sys

rlg, suite = sys.argv[1], sys.argv[2]
p = subprocess.run([rlg, "validate", suite, "--json"], capture_output=True, text=True)
if p.returncode not in (0, 4):
    sys.exit(f"exit status {p.returncode}: {p.stderr}")
report = json.loads(p.stdout)
problems = []
peaks = {(c["run"], c["compensator"]): c for c in report["checks"] if c["check"] == "peak 100s"}
for row in report["table2"]:
    label = f"{row['run']} [{row['compensator']}]"
    peak = row.get("peak_abs_100s_after_dph")
    if not isinstance(peak, float) or not math.isfinite(peak) or peak < 0:
        problems.append(f"{label}: peak_abs_100s_after_dph {peak!r}")
        continue
    check = peaks.get((row["run"], row["compensator"]))
    if check is None or check["value"] != peak:
        problems.append(f"{label}: no 'peak 100s' check with value {peak} ({check})")
for line in problems:
    print(line)
if not problems:
    print(f"{len(report['table2'])} Table 2 rows, each with peak_abs_100s_after_dph and its check")
sys.exit(1 if problems else 0)
