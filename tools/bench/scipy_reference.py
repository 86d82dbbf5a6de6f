#!/usr/bin/python3
"""SciPy reference for the simulator benchmark: solve_ivp (BDF, analytic Jacobian, rtol = atol
= 1e-6, outputs every 1 s) on the default gyro's linear thermal network, thermal part only (no
bias, no noise). Prints simulated gyro-hours per CPU-second.

Needs Debian's python3-scipy (not a project dependency):  /usr/bin/python3 tools/bench/scipy_reference.py
"""
import pathlib
import time
import tomllib

import numpy as np
from scipy.integrate import solve_ivp

root = pathlib.Path(__file__).resolve().parents[2]
gyro = tomllib.loads((root / "scenarios/gyros/default.toml").read_text())
names = [n["name"] for n in gyro["nodes"]]
c = np.array([n["heat_capacity_J_per_K"] for n in gyro["nodes"]])
n = len(names)
K = np.zeros((n, n))
g_amb = np.zeros(n)
for link in gyro["links"]:
    a, b = link["between"]
    g = link["conductance_W_per_K"]
    i = names.index(a)
    K[i, i] += g
    if b == "ambient":
        g_amb[i] += g
    else:
        j = names.index(b)
        K[j, j] += g
        K[i, j] -= g
        K[j, i] -= g
p = np.zeros(n)
for src in gyro["sources"]:
    for node, share in src["shares"].items():
        p[names.index(node)] += share * src["power_W"]
A = -K / c[:, None]
b_amb = g_amb / c
b_p = p / c
hours = 24.0
t_end = hours * 3600.0
t_eval = np.arange(0.0, t_end + 1.0, 1.0)
# The benchmark's ambient (tools/bench/bench_sim.cpp, RampRun): 0 and 60 °C alternating, linear
# in between, breakpoints every 2 h.
pts_t = np.arange(0.0, t_end + 1.0, 7200.0)
pts_v = np.where((pts_t // 7200) % 2 == 1, 60.0, 0.0)


def run(label, ambient):
    start = time.process_time()
    sol = solve_ivp(lambda t, x: A @ x + b_amb * ambient(t) + b_p, (0.0, t_end), np.full(n, ambient(0.0)),
                    method="BDF", t_eval=t_eval, rtol=1e-6, atol=1e-6, jac=lambda t, x: A)
    cpu = time.process_time() - start
    assert sol.success
    print(f"scipy {__import__('scipy').__version__} solve_ivp BDF, {n} nodes, {hours:g} h at 1 s, {label}: "
          f"{cpu:.3f} CPU-s -> {hours / cpu:.0f} gyro-hours per CPU-second")


run("constant 20 °C ambient", lambda t: 20.0)
run("the benchmark's 0/60 °C table ambient", lambda t: np.interp(t, pts_t, pts_v))
