#!/usr/bin/env python3
"""A plug-in compensator for `rlgtherm validate` (protocol: docs/data-format.md, "Plug-in
compensators"), in plain Python without numpy: removes from the bias the straight line in T1
that fits the run best (ordinary least squares of bias_dph on T1).

stdin:  one run as tidy CSV (run,t_s,T_amb,T1,..,bias_dph)
stdout: a CSV with the column compensated_dph, one row per input row (°/h)

It sees the whole run before compensating any sample, which no gyro computer can: it is an
example of the protocol and a baseline, not a causal compensator like Eq. (2)'s."""
import csv
import sys

rows = list(csv.reader(line for line in sys.stdin if not line.startswith("#")))
header, data = rows[0], rows[1:]
t1 = [float(r[header.index("T1")]) for r in data]
bias = [float(r[header.index("bias_dph")]) for r in data]
if len(data) < 2:
    sys.exit(f"linear_t1.py: {len(data)} rows, need at least 2")

n = len(data)
mean_t, mean_b = sum(t1) / n, sum(bias) / n
sxx = sum((t - mean_t) ** 2 for t in t1)
slope = sum((t - mean_t) * (b - mean_b) for t, b in zip(t1, bias)) / sxx if sxx > 0 else 0.0

out = csv.writer(sys.stdout, lineterminator="\n")
out.writerow(["compensated_dph"])
for t, b in zip(t1, bias):
    out.writerow([f"{b - mean_b - slope * (t - mean_t):.6f}"])
