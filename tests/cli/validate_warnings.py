#!/usr/bin/env python3
"""validate_warnings.py RLGTHERM SUITE.toml: a model extrapolated on a run is said in every
output a reader may read, not only in --json: the text's warning lines, --json's per-row
"warnings" (outside_fitted_range true beside it), and each JUnit testcase of the run (a
"warning" property and a "warning:" line of system-out). SUITE compensates fixed+60 beyond the
fitted Ti0 and ramp20to60 with Eq. (2) fitted on warm-ups (dT far beyond the fit's)."""
import json
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

rlg, suite = sys.argv[1], sys.argv[2]
problems = []
expected = {"fixed+60": "Ti0 = 60.00 °C is outside the range", "ramp20to60": "temperature rise dT = T1 - Ti0 reaches"}
with tempfile.TemporaryDirectory() as d:
    xml_path = os.path.join(d, "out.xml")
    text = subprocess.run([rlg, "validate", suite, "--junit", xml_path], capture_output=True, text=True)
    report = json.loads(subprocess.run([rlg, "validate", suite, "--json"], capture_output=True, text=True).stdout)
    root = ET.parse(xml_path).getroot()
for run, words in expected.items():
    if not any(line.startswith("  warning: ") and f"run '{run}': " in line and words in line for line in text.stdout.splitlines()):
        problems.append(f"text: no warning '{words}' for {run}")
    row = next(r for r in report["table2"] if r["run"] == run)
    if not any(words in w for w in row["warnings"]):
        problems.append(f"--json: {run}'s warnings {row['warnings']}")
    cases = [c for c in root.iter("testcase") if c.get("name").endswith(" " + run)]
    if not cases:
        problems.append(f"JUnit: no testcase of {run}")
    for case in cases:
        props = [p.get("value") for p in case.iter("property") if p.get("name") == "warning"]
        if not any(words in p for p in props) or words not in case.find("system-out").text:
            problems.append(f"JUnit: {case.get('name')} does not carry the warning")
quiet = next(r for r in report["table2"] if r["run"] == "fixed+0")
if quiet["warnings"] or quiet["outside_fitted_range"]:
    problems.append(f"fixed+0, inside the fit's range, warned: {quiet['warnings']}")
for p in problems:
    print(p)
if not problems:
    print("the extrapolations are said in the text, --json and JUnit")
sys.exit(1 if problems else 0)
