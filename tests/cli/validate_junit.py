#!/usr/bin/env python3
"""validate_junit.py RLGTHERM SUITE.toml: `validate --junit` writes JUnit XML that parses, with
one testcase per check of `--json`, value/limit/unit as properties equal to the JSON's, and a
<failure> exactly for the failed checks, whose text states the measured value and the limit
written. SUITE must fail a check (exit 4). `--seed N` gives the same bytes twice and other
numbers than another seed."""
import json
import os
import re
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

rlg, suite = sys.argv[1], sys.argv[2]
problems = []


def validate(d, seed, tag):
    xml_path = os.path.join(d, f"{tag}.xml")
    p = subprocess.run([rlg, "validate", suite, "--json", "--seed", str(seed), "--junit", xml_path],
                       capture_output=True, text=True)
    if p.returncode != 4:
        problems.append(f"seed {seed}: exit status {p.returncode}, expected 4 (a failed check): {p.stderr}")
    with open(xml_path, "rb") as f:
        return p.stdout, f.read()


with tempfile.TemporaryDirectory() as d:
    out, xml = validate(d, 11, "a")
    out_again, xml_again = validate(d, 11, "b")
    out_other, _ = validate(d, 12, "c")
    report = json.loads(out)
    root = ET.fromstring(xml)  # raises on XML that is not well-formed
    cases = root.findall("./testsuite/testcase")
    checks = report["checks"]
    if root.tag != "testsuites" or len(cases) != len(checks):
        problems.append(f"{len(cases)} testcases under <{root.tag}>, {len(checks)} checks in --json")
    if int(root.get("failures")) != sum(not c["passed"] for c in checks):
        problems.append(f"failures={root.get('failures')} disagrees with --json")
    for case, check in zip(cases, checks):
        label = f"{check['check']} {check['run']}".strip()
        if case.get("name") != label:
            problems.append(f"testcase {case.get('name')!r} for check {label!r}")
        props = {p.get("name"): p.get("value") for p in case.findall("./properties/property")}
        for key in ("value", "limit"):
            if check.get(key) is not None and float(props.get(key, "nan")) != check[key]:  # both shortest round-trip
                problems.append(f"{label}: property {key} {props.get(key)} != JSON {check[key]}")
        if check.get("unit") != props.get("unit"):
            problems.append(f"{label}: unit {props.get('unit')!r} != JSON {check.get('unit')!r}")
        failure = case.find("failure")
        if (failure is not None) == check["passed"]:
            problems.append(f"{label}: passed={check['passed']} but <failure> {'present' if failure is not None else 'absent'}")
        if failure is not None and failure.text != check["detail"]:
            problems.append(f"{label}: failure text {failure.text!r} != detail {check['detail']!r}")
    bias_failures = [c for c in checks if c["check"] == "bias after" and not c["passed"]]
    if not bias_failures:
        problems.append("no failed bias check")
    for c in bias_failures:
        # The measured value and the limit written (no floor, no reason why not), then what a
        # failure explains: the margin, the run and fit, the key and line of the limit, where to look.
        if not re.fullmatch(r"\|[-+]0\.\d{4}\| > 0\.0001 °/h, the limit written; over the limit by [0-9.e-]+ °/h "
                            r"\(\d+ %\); run 'fixed[+-]\d+', compensated by eq2 of fit 'fixed'; the limit: "
                            r"bias_after_max_dph at \S*tiny_bias_bound\.toml:\d+; look: `rlgtherm validate \S+ --plot DIR` "
                            r"draws the run's bias before and after and its Allan curve", c["detail"]):
            problems.append(f"failed bias check text: {c['detail']!r}")
    if out != out_again or xml != xml_again:
        problems.append("the same --seed gave different output")
    if json.loads(out_other)["table2"] == report["table2"]:
        problems.append("--seed 12 gave the numbers of --seed 11")

for p in problems:
    print(p)
if not problems:
    print(f"JUnit: {len(cases)} testcases, {root.get('failures')} failures, as in --json; --seed reproducible")
sys.exit(1 if problems else 0)
