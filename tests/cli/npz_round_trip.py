#!/usr/bin/env python3
"""npz_round_trip.py RLGTHERM SCENARIO.toml: `simulate -o x.npz` writes what numpy.load reads
(allow_pickle=False) and holds the same runs, columns and values as `simulate -o x.csv` with the
same seed: the CSV's values are the npz's rounded to the CSV's fixed precision (io/csv.cpp:
temperatures T* 4 decimals, other columns 6, t_s exact), and the header comments match."""
import re
import csv
import os
import subprocess
import sys
import tempfile

import numpy as np

rlg, scenario = sys.argv[1], sys.argv[2]
problems = []
with tempfile.TemporaryDirectory() as d:
    paths = {ext: os.path.join(d, f"out.{ext}") for ext in ("csv", "npz")}
    for path in paths.values():
        subprocess.run([rlg, "simulate", scenario, "--seed", "7", "-o", path], check=True, capture_output=True)
    comments, rows = [], {}
    with open(paths["csv"], newline="") as f:
        lines = f.read().splitlines()
    comments = [line[1:].strip() for line in lines if line.startswith("#")]
    reader = csv.reader(line for line in lines if not line.startswith("#"))
    header = next(reader)
    for row in reader:
        rows.setdefault(row[0], []).append([float(v) for v in row[1:]])
    with np.load(paths["npz"], allow_pickle=False) as z:
        runs = list(z["runs"])
        if runs != list(rows):
            problems.append(f"runs {runs} != CSV's {list(rows)}")
        if [c.strip() for c in z["comments"]] != comments:
            problems.append(f"comments {list(z['comments'])} != CSV's {comments}")
        keys = set(z.files)
        for run in runs:
            want = {f"{run}/{name}" for name in header[1:]}
            if not want <= keys:
                problems.append(f"run {run}: missing {sorted(want - keys)}")
                continue
            table = np.array(rows[run])
            for j, name in enumerate(header[1:]):
                a = z[f"{run}/{name}"]
                if a.dtype != np.float64 or a.shape != (len(table),):
                    problems.append(f"{run}/{name}: {a.dtype} {a.shape}, want float64 ({len(table)},)")
                    continue
                # The CSV rounds temperatures to 4 decimals and other columns to 6: it may differ from
                # the exact value by half its last digit (1e-9 relative for the decimal's own double);
                # t_s is written in full.
                half = 0.0 if name == "t_s" else 0.5e-4 if re.match(r"T(\d|_)", name) else 0.5e-6
                err = np.max(np.abs(a - table[:, j]))
                if err > half * (1 + 1e-9):
                    problems.append(f"{run}/{name}: |npz - csv| up to {err:g} > {half:g}")
if problems:
    sys.exit("npz_round_trip: " + "\n".join(problems))
print(f"npz_round_trip: {len(runs)} runs, npz equals the CSV to its precision")
