#!/usr/bin/python3
"""First steps with rlgtherm from Python: simulate the seed paper's fixed-ambient tests, fit
Eq. (2), try a compensator of your own in numpy, and score both with the same metrics.

Run from the repository (after the build):
    PYTHONPATH=build/python /usr/bin/python3 python/examples/first_steps.py
"""
from pathlib import Path

import numpy as np
import rlgtherm

REPO = Path(__file__).resolve().parents[2]
HELD_OUT = "fixed+60"  # the paper's suite holds out the +60 °C run (scenarios/paper-suite.toml)
B0_WINDOW_S = 120.0  # as Eq. (2)'s B0


# Your own compensator: bias - B0 regressed on the warm-up of T1 and its rate. Causal, as a gyro
# computer runs it: sample k uses samples 0..k only (a test checks it on every prefix of a run).
def rate(t, x):
    """dx/dt from each sample and the one before (0 at power-on): a backward difference, unlike
    np.gradient's central one, which reads the next sample."""
    return np.concatenate([[0.0], np.diff(x) / np.diff(t)])


def features(run):
    t, T1 = run.t_s, run["T1"]
    return np.column_stack([T1 - T1[0], rate(t, T1) * 60.0])  # °C, °C/min


def b0(run):
    """B0 as the Compensator keeps it: the running mean of the bias over the first window, then
    frozen (°/h, one value per sample)."""
    t, bias = run.t_s, run["bias_dph"]
    running = np.cumsum(bias) / np.arange(1, len(bias) + 1)
    in_window = t < t[0] + B0_WINDOW_S
    return np.where(in_window, running, running[in_window.sum() - 1])


def fit_mine(data, train):
    """The least-squares coefficients of features() over the training runs."""
    X = np.vstack([features(data[i]) for i in train])
    y = np.concatenate([data[i]["bias_dph"] - b0(data[i]) for i in train])
    beta, *_ = np.linalg.lstsq(X, y, rcond=None)
    return beta


def mine(run, beta):
    return run["bias_dph"] - b0(run) - features(run) @ beta


def main():
    # 1. Ten warm-ups of 2 h at 1 s, after a soak at -30 ... +60 °C: the columns of
    #    `rlgtherm simulate` (t_s in s, T_amb and T1..T4 in °C, bias_dph in °/h) as numpy arrays.
    data = rlgtherm.simulate(str(REPO / "scenarios/paper-fixed.toml"), seed=1)
    train = [run.id for run in data if run.id != HELD_OUT]

    # 2. The paper's Eq. (2) for the pair (T1, T2), fitted on nine runs.
    coeffs = rlgtherm.fit(data, pair=("T1", "T2"), runs=train)
    eq2 = rlgtherm.Compensator(coeffs)

    # 3. Yours, fitted on the same nine runs.
    beta = fit_mine(data, train)

    # 4. Both scored by the library's Table 2 metrics (what `rlgtherm compensate --json` reports).
    print(f"{'run':<10} {'bias before':>12} {'Eq.(2) after':>13} {'mine after':>11}   "
          f"{'100 s stability: before':>23} {'Eq.(2)':>8} {'mine':>8}   (°/h)")
    for run in data:
        a = rlgtherm.evaluate(run, eq2.compensate_run(run), coefficients=coeffs)
        b = rlgtherm.evaluate(run, mine(run, beta))
        print(f"{run.id:<10} {a['bias_before_dph']:12.4f} {a['bias_after_dph']:13.4f} {b['bias_after_dph']:11.4f}   "
              f"{a['stability_100s_before_dph']:23.4f} {a['stability_100s_after_dph']:8.4f} "
              f"{b['stability_100s_after_dph']:8.4f}" + ("   held out" if run.id == HELD_OUT else ""))


if __name__ == "__main__":
    main()
