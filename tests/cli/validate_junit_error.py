#!/usr/bin/env python3
"""validate_junit_error.py RLGTHERM STATUS SUITE.toml: a validate that cannot run (exit STATUS:
2 for a configuration error, 3 for a fit the data cannot identify) still writes its --junit file,
well-formed, with one testcase "configuration" whose <error> carries the message printed on
stderr, so that CI shows the error rather than no report; and no --json output on stdout."""
import os
import subprocess
import sys
import tempfile
import xml.etree.ElementTree as ET

rlg, status, suite = sys.argv[1], int(sys.argv[2]), sys.argv[3]
problems = []
with tempfile.TemporaryDirectory() as d:
    path = os.path.join(d, "out.xml")
    p = subprocess.run([rlg, "validate", suite, "--json", "--junit", path], capture_output=True, text=True)
    if p.returncode != status:
        problems.append(f"exit status {p.returncode}, expected {status}")
    if p.stdout:
        problems.append(f"stdout not empty: {p.stdout[:200]!r}")
    if not os.path.exists(path):
        problems.append("no JUnit file")
    else:
        root = ET.parse(path).getroot()
        cases = root.findall("./testsuite/testcase")
        errors = [c.find("error") for c in cases]
        if root.get("errors") != "1" or len(cases) != 1 or errors[0] is None or cases[0].get("name") != "configuration":
            problems.append(f"expected one errored testcase 'configuration': {ET.tostring(root)[:300]!r}")
        else:
            message = errors[0].get("message")
            if not message or message not in p.stderr or errors[0].text != message:
                problems.append(f"<error> {message!r} is not the message on stderr {p.stderr!r}")
for line in problems:
    print(line)
if not problems:
    print(f"exit {status} with a JUnit file of one errored testcase: {p.stderr.strip()[:160]}")
sys.exit(1 if problems else 0)
