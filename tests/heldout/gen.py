#!/usr/bin/python3
"""tests/heldout/gen.py: an independent generator of blind test data for `rlgtherm diagnose`.

Written from rlgtherm's documentation only (docs/physics.md, docs/data-format.md,
docs/diagnosis.md, scenarios/README.md and the nominal gyro file); nothing under sim/,
diagnosis/, model/, validation/, tests/ or python/ was read.  numpy + scipy only.

    /usr/bin/python3 gen.py --out DIR [--jobs 2] [--sample-period 60]   # the 34 cases
    /usr/bin/python3 gen.py --out DIR --only bias.gradient --seeds 2
    /usr/bin/python3 gen.py --selftest          # integrator and noise checks

Each case directory holds data.csv (tidy CSV), nominal.toml (the unperturbed nominal gyro,
copied verbatim) and truth.json.  See README.md for the physics, the size rule and the noise.
"""
import argparse
import copy
import json
import math
import multiprocessing
import os
import shutil
import sys
import tomllib
import zlib

import numpy as np
from scipy.integrate import odeint
from scipy.linalg import expm
from scipy.optimize import brentq

NOMINAL_PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scenarios", "gyros",
                            "default.toml")   # read only, copied verbatim
SIGMA_SB = 5.670374419e-8       # W/(m^2 K^4)
KELVIN = 273.15
DT = 10.0                       # sample period, s (--sample-period sets it)
BLOCK_S = 100.0                 # averaging block of the size rule, s
MC_REPS = 40                    # noise realisations for the 100 s noise sd

EFFECTS = ["thermal.missing_link", "thermal.radiation", "sensor.lag", "sensor.offset",
           "bias.temperature_rate", "bias.hysteresis", "bias.mode_hop", "bias.gradient"]
K_RULE = {"thermal.missing_link": 9.0, "sensor.lag": 9.0}
K_DEFAULT = 4.5

# Physically sensible targets in the default (4-node) gyro, see README.md.
TARGETS = {
    # pairs with no link in the nominal, and electrodes to the chamber (leads, openings)
    "thermal.missing_link": ["anode-cathode", "cathode-cabinet", "anode-ambient", "cathode-ambient"],
    # block/electrodes radiating to the inside of the case; block through the openings; case to
    # the chamber walls
    "thermal.radiation": ["block-cabinet", "anode-cabinet", "cathode-cabinet", "block-ambient",
                          "cabinet-ambient"],
    "sensor.lag": ["T1", "T2", "T3", "T4"],
    "sensor.offset": ["T1", "T2", "T3", "T4"],
    "bias.temperature_rate": ["block", "anode", "cathode", "cabinet"],
    "bias.hysteresis": ["block", "anode", "cathode", "cabinet"],
    "bias.mode_hop": ["block"],
    # every node pair except anode-block, which the nominal's Langmuir term already has
    "bias.gradient": ["anode-cathode", "anode-cabinet", "cathode-block", "cathode-cabinet",
                      "block-cabinet"],
}
PLAUSIBLE = {  # docs/physics.md, effect catalog
    "conductance_W_per_K": (1e-6, 10.0),
    "emissivity_area_m2": (1e-6, 0.2),
    "time_constant_s": (0.1, 600.0),
    "offset_C": (-3.0, 3.0),
    "k_dph_per_C_per_min": (-1.0, 1.0),
    "k_dph_per_C": (-1.0, 1.0),
    "k_heating_dph_per_C": (-0.5, 0.5),
    "k_cooling_dph_per_C": (-0.5, 0.5),
    "step_dph": (-1.0, 1.0),
}


# --------------------------------------------------------------------------- gyro file
def load_gyro(path=NOMINAL_PATH):
    with open(path, "rb") as f:
        d = tomllib.load(f)
    if d.get("effects"):
        raise ValueError("the nominal gyro must not carry [[effects]]")
    g = {"name": d.get("name", "gyro")}
    g["nodes"] = [n["name"] for n in d["nodes"]]
    g["C"] = np.array([float(n["heat_capacity_J_per_K"]) for n in d["nodes"]])
    g["links"] = [[l["between"][0], l["between"][1], float(l["conductance_W_per_K"])]
                  for l in d.get("links", [])]
    g["radiation"] = [[r["between"][0], r["between"][1], float(r["emissivity_area_m2"])]
                      for r in d.get("radiation", [])]
    g["sources"] = []
    for s in d.get("sources", []):
        if s.get("driven_by_data", False):
            raise ValueError("data-driven sources are not supported")
        g["sources"].append({"name": s["name"], "P": float(s.get("power_W", 0.0)),
                             "shares": {k: float(v) for k, v in s["shares"].items()},
                             "gain": float(s.get("gain", 1.0))})
    g["sensors"] = []
    for ch in sorted(d["sensors"].keys()):  # the loader's order: byte order of channel names
        s = d["sensors"][ch]
        g["sensors"].append({"ch": ch, "node": s["node"], "noise": float(s.get("noise_C", 0.0)),
                             "res": float(s.get("resolution_C", 0.0))})
    b = d.get("bias", {})
    g["bias"] = {
        "node": b["node"], "reference_C": float(b.get("reference_C", 20.0)),
        "b0": float(b.get("b0_dph", 0.0)), "b1": float(b.get("b1_dph_per_C", 0.0)),
        "b2": float(b.get("b2_dph_per_C2", 0.0)),
        "dI": float(b.get("langmuir_current_imbalance_mA", 0.0)),
        "kI": float(b.get("langmuir_dph_per_mA", 0.0)),
        "cT": float(b.get("langmuir_temperature_coeff_per_C", 0.0)),
        "lgrad": [[lg["between"][0], lg["between"][1], float(lg["k_dph_per_C"])]
                  for lg in b.get("langmuir_gradient", [])],
        "L": float(b.get("path_length_m", 0.43)), "alpha": float(b.get("cte_per_C", 5e-8)),
        "lam": float(b.get("wavelength_m", 632.8e-9)),
        "kplc": float(b.get("plc_dph_per_wavelength", 0.0)),
    }
    n = d.get("noise", {})
    g["noise"] = {
        "arw": float(n.get("arw_deg_per_sqrt_h", 0.0)),
        "B": float(n.get("bias_instability_dph", 0.0)),
        "model": n.get("instability_model", "flicker"),
        "gm_time": float(n.get("gauss_markov_time_s", 3600.0)),
        "rrw": float(n.get("rrw_deg_per_h_per_sqrt_h", 0.0)),
        "Q": float(n.get("quantization_arcsec", 0.0)),
        "turn_on": float(n.get("turn_on_sigma_dph", 0.0)),
    }
    g["rel_unc"] = float(d.get("calibration", {}).get("relative_uncertainty", 0.05))
    return g


def perturb(g, rng):
    """The true gyro: C, G and P log-normal about the nominal with the file's relative
    uncertainty; b0 and the Langmuir gradient spread as scenarios/paper-population.toml does."""
    t = copy.deepcopy(g)
    s = g["rel_unc"]
    drawn = {}
    z = rng.standard_normal(len(g["C"]))
    t["C"] = g["C"] * np.exp(s * z)
    for i, nm in enumerate(g["nodes"]):
        drawn[f"nodes.{nm}.heat_capacity_J_per_K"] = float(t["C"][i])
    for l in t["links"]:
        l[2] = l[2] * math.exp(s * rng.standard_normal())
        drawn[f"links.{l[0]}-{l[1]}.conductance_W_per_K"] = l[2]
    for r in t["radiation"]:
        r[2] = r[2] * math.exp(s * rng.standard_normal())
        drawn[f"radiation.{r[0]}-{r[1]}.emissivity_area_m2"] = r[2]
    for src in t["sources"]:
        src["P"] = src["P"] * math.exp(s * rng.standard_normal())
        drawn[f"sources.{src['name']}.power_W"] = src["P"]
    t["bias"]["b0"] = g["bias"]["b0"] + 0.3 * rng.standard_normal()
    drawn["bias.b0_dph"] = t["bias"]["b0"]
    for lg in t["bias"]["lgrad"]:
        lg[2] = lg[2] * (1.0 + 0.2 * rng.standard_normal())
        drawn[f"bias.langmuir_gradient.{lg[0]}-{lg[1]}.k_dph_per_C"] = lg[2]
    return t, drawn


# --------------------------------------------------------------------------- network
class Network:
    """C dT/dt = -L T - diag(g_amb) (T - T_amb) + p - radiation;  sensor lags as extra states."""

    def __init__(self, g, extra_links=(), extra_rad=(), lags=None):
        self.nodes = list(g["nodes"])
        n = len(self.nodes)
        self.n = n
        idx = {nm: i for i, nm in enumerate(self.nodes)}
        self.idx = idx
        Kc = np.zeros((n, n))
        gamb = np.zeros(n)
        for a, b, G in list(g["links"]) + list(extra_links):
            if b == "ambient":
                gamb[idx[a]] += G
            elif a == "ambient":
                gamb[idx[b]] += G
            else:
                Kc[idx[a], idx[b]] += G
                Kc[idx[b], idx[a]] += G
        lap = np.diag(Kc.sum(axis=1)) - Kc
        Cinv = 1.0 / g["C"]
        p = np.zeros(n)
        for s in g["sources"]:
            for nm, sh in s["shares"].items():
                p[idx[nm]] += sh * s["P"] * s["gain"]
        self.rad = []
        for a, b, eA in list(g["radiation"]) + list(extra_rad):
            if a == "ambient":
                a, b = b, a
            self.rad.append((idx[a], -1 if b == "ambient" else idx[b], eA))
        # sensor states
        self.lag_states = []          # (channel, node index, tau)
        for ch, (node, tau) in (lags or {}).items():
            self.lag_states.append((ch, idx[node], float(tau)))
        nx = n + len(self.lag_states)
        self.nx = nx
        A = np.zeros((nx, nx))
        A[:n, :n] = -(lap + np.diag(gamb)) * Cinv[:, None]
        for k, (ch, ni, tau) in enumerate(self.lag_states):
            A[n + k, ni] = 1.0 / tau
            A[n + k, n + k] = -1.0 / tau
        Bv = np.zeros(nx)
        Bv[:n] = gamb * Cinv
        cv = np.zeros(nx)
        cv[:n] = p * Cinv
        self.A, self.B, self.c, self.Cinv = A, Bv, cv, Cinv

    def state_of_channel(self, ch, node):
        for k, (c, ni, tau) in enumerate(self.lag_states):
            if c == ch:
                return self.n + k
        return self.idx[node]

    def rhs(self, t, x, u):
        f = self.A @ x + self.B * u + self.c
        for i, j, eA in self.rad:
            Ti = x[i] + KELVIN
            Tj = (u if j < 0 else x[j]) + KELVIN
            q = SIGMA_SB * eA * (Ti ** 4 - Tj ** 4)
            f[i] -= q * self.Cinv[i]
            if j >= 0:
                f[j] += q * self.Cinv[j]
        return f

    def jac(self, t, x):
        J = self.A.copy()
        for i, j, eA in self.rad:
            di = 4 * SIGMA_SB * eA * (x[i] + KELVIN) ** 3
            J[i, i] -= di * self.Cinv[i]
            if j >= 0:
                dj = 4 * SIGMA_SB * eA * (x[j] + KELVIN) ** 3
                J[i, j] += dj * self.Cinv[i]
                J[j, i] += di * self.Cinv[j]
                J[j, j] -= dj * self.Cinv[j]
        return J

    def simulate(self, run, force_ode=False):
        """States at t = 0, DT, ..., duration; power on at t = 0 after a soak at T_amb(0)."""
        t = run["t"]
        u = run["Tamb"]
        N = len(t)
        X = np.empty((self.nx, N))
        x = np.full(self.nx, u[0])
        X[:, 0] = x
        if not self.rad and not force_ode:
            # exact: z = [x, u, r, 1], z' = M z for T_amb linear over each sample step
            nx = self.nx
            M = np.zeros((nx + 3, nx + 3))
            M[:nx, :nx] = self.A
            M[:nx, nx] = self.B
            M[:nx, nx + 2] = self.c
            M[nx, nx + 1] = 1.0
            E = expm(M * DT)
            Exx, Exu, Exr, Ex1 = E[:nx, :nx], E[:nx, nx], E[:nx, nx + 1], E[:nx, nx + 2]
            r = np.diff(u) / DT
            for k in range(N - 1):
                x = Exx @ x + Exu * u[k] + Exr * r[k] + Ex1
                X[:, k + 1] = x
        else:
            bp = run["bp_idx"]  # sample indices of the ambient's breakpoints (0 and N-1 included)
            for a, b in zip(bp[:-1], bp[1:]):
                ta, tb = t[a], t[b]
                ua, rate = u[a], (u[b] - u[a]) / (tb - ta)
                # ODEPACK's LSODA (compiled; Adams or BDF as the stiffness asks, with the
                # analytic Jacobian): a tenth of solve_ivp's Radau time at 1e-10, and within
                # 1e-9 C of the exact solution at 1e-12 (the self-test).
                y, info = odeint(lambda xx, tt: self.rhs(tt, xx, ua + rate * (tt - ta)), x, t[a:b + 1],
                                 Dfun=lambda xx, tt: self.jac(tt, xx), rtol=1e-12, atol=1e-12,
                                 mxstep=100000, full_output=True)
                if info["message"] != "Integration successful.":
                    raise RuntimeError(info["message"])
                X[:, a + 1:b + 1] = y[1:].T
                x = y[-1]
        dX = np.empty_like(X)
        for k in range(N):
            dX[:, k] = self.rhs(t[k], X[:, k], u[k])
        return X, dX


# --------------------------------------------------------------------------- schedule
def _round10(s):
    return max(DT, round(s / DT) * DT)


class Profile:
    def __init__(self, T0):
        self.pts = [(0.0, float(T0))]

    @property
    def t(self):
        return self.pts[-1][0]

    @property
    def T(self):
        return self.pts[-1][1]

    def hold(self, seconds):
        self.pts.append((self.t + _round10(seconds), self.T))

    def ramp(self, target, rate_C_per_min):
        dur = max(DT, math.ceil(abs(target - self.T) / rate_C_per_min * 60.0 / DT) * DT)
        self.pts.append((self.t + dur, float(target)))

    def hold_until(self, total):
        total = _round10(total)
        if total > self.t:
            self.pts.append((total, self.T))


def make_schedule(rng):
    """Four chamber runs, 6-10 h each, ambient within -20...+50 C, ramps <= 3 C/min."""
    U = rng.uniform
    runs = []
    # run1: warm-up at room temperature, ramp up, dwell, ramp down to cold, dwell, back
    p = Profile(round(U(18, 24), 1))
    p.hold(U(1.5, 2.0) * 3600)
    p.ramp(round(U(44, 50), 1), U(0.8, 1.5))
    p.hold(U(50, 70) * 60)
    p.ramp(round(U(-20, -15), 1), U(0.8, 1.5))
    p.hold(U(60, 80) * 60)
    p.ramp(round(U(15, 25), 1), U(1.5, 2.5))
    p.hold_until(U(8.0, 9.5) * 3600)
    runs.append(p)
    # run2: cold soak, warm-up, staircase of fast ramps ("steps") with dwells, slow return
    p = Profile(round(U(-20, -12), 1))
    p.hold(U(1.5, 2.0) * 3600)
    while p.T < 32:
        p.ramp(round(min(p.T + U(12, 18), 50.0), 1), U(2.5, 3.0))
        p.hold(U(50, 70) * 60)
    p.ramp(round(U(15, 25), 1), U(0.8, 1.2))
    p.hold_until(max(p.t + 1800, U(8.0, 9.5) * 3600))
    runs.append(p)
    # run3: hot soak, warm-up, slow cooling ramp, dwell, ramp up, fast drop, dwell
    p = Profile(round(U(40, 50), 1))
    p.hold(U(1.5, 2.0) * 3600)
    p.ramp(round(U(-10, 0), 1), U(0.3, 0.6))
    p.hold(U(50, 70) * 60)
    p.ramp(round(U(25, 35), 1), U(1.5, 2.5))
    p.hold(U(50, 70) * 60)
    p.ramp(round(U(5, 15), 1), U(2.5, 3.0))
    p.hold_until(max(p.t + 1800, U(8.0, 9.5) * 3600))
    runs.append(p)
    # run4: cool soak, warm-up, triangle up and down at one rate, return, dwell
    p = Profile(round(U(0, 10), 1))
    p.hold(U(1.5, 2.0) * 3600)
    rate = U(0.5, 1.0)
    p.ramp(round(U(35, 45), 1), rate)
    p.ramp(round(U(-5, 5), 1), rate)
    p.ramp(20.0, U(1.0, 1.5))
    p.hold_until(max(p.t + 1800, U(6.5, 8.0) * 3600))
    runs.append(p)
    out = []
    for k, p in enumerate(runs):
        pts = np.array(p.pts)
        D = pts[-1, 0]
        assert 6 * 3600 <= D <= 10 * 3600, D
        t = np.arange(0.0, D + DT / 2, DT)
        Tamb = np.interp(t, pts[:, 0], pts[:, 1])
        bp_idx = sorted(set(int(round(x / DT)) for x in pts[:, 0]))
        out.append({"id": f"run{k + 1}", "t": t, "Tamb": Tamb, "points": p.pts,
                    "bp_idx": bp_idx})
    return out


# --------------------------------------------------------------------------- bias
def mode_spacing(bias):
    return bias["lam"] / (bias["L"] * bias["alpha"])


def bias_clean(g, net, run, X, dX, effect):
    """Deterministic bias (deg/h) at the sample times from the true node temperatures."""
    b = g["bias"]
    idx = net.idx
    Tb = X[idx[b["node"]]]
    d = Tb - b["reference_C"]
    B = b["b0"] + b["b1"] * d + b["b2"] * d ** 2
    flow = b["kI"] * b["dI"] + sum(k * (X[idx[a]] - X[idx[c]]) for a, c, k in b["lgrad"])
    B = B + (1.0 + b["cT"] * d) * flow
    # path-length control: travel u = (T_b - T_lock)/spacing - m, B_PLC = k_plc u
    S = mode_spacing(b)
    Tb0 = Tb[0]
    hop = effect if (effect and effect["name"] == "bias.mode_hop") else None
    if hop is None:
        B = B + b["kplc"] * (Tb - Tb0) / S
    else:
        pr = hop["parameters"]
        S = pr["mode_spacing_C"]
        R = pr["range_modes"]
        c0 = pr.get("centre_C")
        Tlock = Tb0 if c0 is None else c0 + round((Tb0 - c0) / S) * S
        m = 0
        mm = np.empty(len(Tb))
        uu = np.empty(len(Tb))
        for k in range(len(Tb)):
            uk = (Tb[k] - Tlock) / S - m
            while uk > R:
                m += 1
                uk -= 1.0
            while uk < -R:
                m -= 1
                uk += 1.0
            mm[k] = m
            uu[k] = uk
        B = B + b["kplc"] * uu + pr["step_dph"] * mm
    if effect:
        nm, pr, tg = effect["name"], effect["parameters"], effect["target"]
        if nm == "bias.temperature_rate":
            B = B + pr["k_dph_per_C_per_min"] * dX[idx[tg]] * 60.0
        elif nm == "bias.gradient":
            a, c = tg.split("-")
            B = B + pr["k_dph_per_C"] * (X[idx[a]] - X[idx[c]])
        elif nm == "bias.hysteresis":
            dT = np.diff(X[idx[tg]])
            inc = pr["k_heating_dph_per_C"] * np.maximum(dT, 0) + \
                pr["k_cooling_dph_per_C"] * np.minimum(dT, 0)
            B = B + np.concatenate([[0.0], np.cumsum(inc)])
    return B


# --------------------------------------------------------------------------- clean outputs
def network_for(g, effect):
    extra_links, extra_rad, lags = [], [], {}
    if effect:
        nm, tg, pr = effect["name"], effect["target"], effect["parameters"]
        if nm == "thermal.missing_link":
            a, b = tg.split("-")
            extra_links.append([a, b, pr["conductance_W_per_K"]])
        elif nm == "thermal.radiation":
            a, b = tg.split("-")
            extra_rad.append([a, b, pr["emissivity_area_m2"]])
        elif nm == "sensor.lag":
            node = [s["node"] for s in g["sensors"] if s["ch"] == tg][0]
            lags[tg] = (node, pr["time_constant_s"])
    return Network(g, extra_links, extra_rad, lags)


def clean_outputs(g, schedule, effect):
    """Noise-free channels per run: {run_id: {"T1": .., ..., "bias_dph": .., "_X": nodes}}."""
    net = network_for(g, effect)
    out = {}
    for run in schedule:
        X, dX = net.simulate(run)
        r = {}
        for s in g["sensors"]:
            y = X[net.state_of_channel(s["ch"], s["node"])].copy()
            if effect and effect["name"] == "sensor.offset" and effect["target"] == s["ch"]:
                y = y + effect["parameters"]["offset_C"]
            r[s["ch"]] = y
        r["bias_dph"] = bias_clean(g, net, run, X[:net.n], dX[:net.n], effect)
        r["_X"] = X[:net.n]
        out[run["id"]] = r
    return out


def channels(g):
    return [s["ch"] for s in g["sensors"]] + ["bias_dph"]


def concat(clean, ch):
    return np.concatenate([clean[k][ch] for k in clean])


# --------------------------------------------------------------------------- noise
def gm_unit_avar(tau, Tc):
    """Allan variance of a first-order Gauss-Markov rate of unit sd, correlation time Tc."""
    x = tau / Tc
    return (2 * x - 3 + 4 * np.exp(-x) - np.exp(-2 * x)) / x ** 2


def instability_terms(noise):
    """[(sigma, Tc)] of the bias-instability Gauss-Markov terms."""
    B = noise["B"]
    if B <= 0:
        return []
    if noise["model"] == "gauss_markov":
        return [(B, noise["gm_time"])]
    Tcs = 10.0 ** np.arange(1.0, 5.0 + 1e-9, 0.5)        # 10 s ... 1e5 s, half a decade apart
    taus = np.logspace(np.log10(30.0), np.log10(3e4), 61)
    av = sum(gm_unit_avar(taus, Tc) for Tc in Tcs)
    s = 0.664 * B / math.exp(np.mean(0.5 * np.log(av)))  # geometric-mean flat floor = 0.664 B
    return [(s, float(Tc)) for Tc in Tcs]


def gm_interval_means(rng, N, sigma, Tc, dt):
    """Means over consecutive intervals dt of a stationary OU process (exact)."""
    a = dt / Tc
    phi = math.exp(-a)
    v1 = sigma ** 2 * (-math.expm1(-2 * a))
    if a < 1e-3:
        f = (2.0 / 3.0) * a ** 3 - 0.5 * a ** 4 + (7.0 / 30.0) * a ** 5
    else:
        f = 2 * a - 3 + 4 * phi - phi ** 2
    v2 = sigma ** 2 * Tc ** 2 * f
    c12 = sigma ** 2 * Tc * math.expm1(-a) ** 2
    L = np.linalg.cholesky(np.array([[v1, c12], [c12, v2]]) + np.diag([0.0, 1e-300]))
    z = rng.standard_normal((2, N))
    e = L @ z
    x = np.empty(N)
    x[0] = sigma * rng.standard_normal()
    if N > 1:
        from scipy.signal import lfilter
        x[1:] = lfilter([1.0], [1.0, -phi], e[0, :N - 1], zi=[phi * x[0]])[0]
    integral = Tc * (-math.expm1(-a)) * x + e[1]
    return integral / dt


def bias_noisy(rng, clean, noise, dt, terms):
    N = len(clean)
    rate = clean + noise["turn_on"] * rng.standard_normal()
    rate = rate + (60.0 * noise["arw"] / math.sqrt(dt)) * rng.standard_normal(N)
    for s, Tc in terms:
        rate = rate + gm_interval_means(rng, N, s, Tc, dt)
    if noise["rrw"] > 0:
        rate = rate + np.cumsum(noise["rrw"] * math.sqrt(dt) / 60.0 * rng.standard_normal(N))
    Q = noise["Q"]
    if Q > 0:
        # the angle (1 deg/h x 1 s = 1 arcsec) is read in whole pulses of Q arcsec
        theta = rng.uniform(0, Q) + np.cumsum(rate * dt)
        pulses = np.floor(theta / Q)
        prev = np.concatenate([[0.0], pulses[:-1]])
        rate = (pulses - prev) * Q / dt
    return rate


def temp_noisy(rng, clean, noise_C, res_C):
    y = clean + noise_C * rng.standard_normal(len(clean))
    if res_C > 0:
        y = np.floor(y / res_C + 0.5) * res_C
    return y


def add_noise(g, clean, rng, terms):
    out = {}
    for rid, r in clean.items():
        o = {}
        for s in g["sensors"]:
            o[s["ch"]] = temp_noisy(rng, r[s["ch"]], s["noise"], s["res"])
        o["bias_dph"] = bias_noisy(rng, r["bias_dph"], g["noise"], DT, terms)
        out[rid] = o
    return out


def block_means(x, n):
    m = len(x) // n
    return x[:m * n].reshape(m, n).mean(axis=1)


def noise_100s(g, clean, rng, terms, reps=MC_REPS):
    """sd of the 100 s block means of (noisy - clean), pooled over the record's runs (each run
    cut into whole 100 s blocks from power-on), about the record's mean, as an rms over
    `reps` Monte Carlo realisations of the channel's full noise."""
    nb = int(round(BLOCK_S / DT))
    acc = {ch: [] for ch in channels(g)}
    for _ in range(reps):
        noisy = add_noise(g, clean, rng, terms)
        for ch in channels(g):
            bm = np.concatenate([block_means(noisy[k][ch] - clean[k][ch], nb) for k in clean])
            acc[ch].append(np.var(bm, ddof=1))
    return {ch: float(math.sqrt(np.mean(v))) for ch, v in acc.items()}


def allan_100s_bias(noise, terms):
    """Analytic Allan deviation at 100 s of the bias noise (for the record only)."""
    tau = 100.0
    v = (60.0 * noise["arw"]) ** 2 / tau + sum(s ** 2 * gm_unit_avar(tau, Tc) for s, Tc in terms)
    v += (noise["rrw"] / 60.0) ** 2 * tau / 3.0 + 3 * noise["Q"] ** 2 / tau ** 2
    return math.sqrt(v)


# --------------------------------------------------------------------------- size rule
def ratios(g, base, withfx, sd):
    out = {}
    for ch in channels(g):
        diff = concat(withfx, ch) - concat(base, ch)
        out[ch] = float(math.sqrt(np.mean(diff ** 2)) / sd[ch])
    return out


def size_effect(g, schedule, base, sd, effect, K, rng):
    """Scale the effect so that max over channels of RMS(contribution)/sd100 = K."""
    nm, pr = effect["name"], effect["parameters"]

    def ratio_at(val, key):
        e = copy.deepcopy(effect)
        e["parameters"][key] = val
        return ratios(g, base, clean_outputs(g, schedule, e), sd)

    if nm in ("thermal.missing_link", "thermal.radiation", "sensor.lag"):
        key = {"thermal.missing_link": "conductance_W_per_K",
               "thermal.radiation": "emissivity_area_m2",
               "sensor.lag": "time_constant_s"}[nm]
        lo, hi = {"conductance_W_per_K": (1e-7, 50.0), "emissivity_area_m2": (1e-7, 5.0),
                  "time_constant_s": (1e-3, 2e4)}[key]
        f = lambda lv: max(ratio_at(math.exp(lv), key).values()) - K
        flo, fhi = f(math.log(lo)), f(math.log(hi))
        if not (flo < 0 < fhi):
            return None
        lv = brentq(f, math.log(lo), math.log(hi), xtol=1e-7, rtol=1e-10)
        pr[key] = float(math.exp(lv))
    elif nm == "sensor.offset":
        sign = 1.0 if rng.uniform() < 0.5 else -1.0
        pr["offset_C"] = sign * K * sd[effect["target"]]
    elif nm in ("bias.temperature_rate", "bias.gradient"):
        key = "k_dph_per_C_per_min" if nm == "bias.temperature_rate" else "k_dph_per_C"
        sign = 1.0 if rng.uniform() < 0.5 else -1.0
        unit = max(ratio_at(1.0, key).values())
        pr[key] = sign * K / unit
    elif nm == "bias.hysteresis":
        sign = 1.0 if rng.uniform() < 0.5 else -1.0
        e = copy.deepcopy(effect)
        e["parameters"].update(k_heating_dph_per_C=0.5, k_cooling_dph_per_C=-0.5)
        unit = max(ratios(g, base, clean_outputs(g, schedule, e), sd).values())
        dk = sign * K / unit
        pr["k_heating_dph_per_C"] = 0.5 * dk
        pr["k_cooling_dph_per_C"] = -0.5 * dk
    elif nm == "bias.mode_hop":
        # contribution = step * m(t) + v(t), v: the PLC's own reset and the power-on lock;
        # RMS^2 is a quadratic in the step: solve for the drawn sign.
        sign = 1.0 if rng.uniform() < 0.5 else -1.0
        e0 = copy.deepcopy(effect)
        e0["parameters"]["step_dph"] = 0.0
        e1 = copy.deepcopy(effect)
        e1["parameters"]["step_dph"] = 1.0
        b0 = concat(base, "bias_dph")
        v = concat(clean_outputs(g, schedule, e0), "bias_dph") - b0
        m = concat(clean_outputs(g, schedule, e1), "bias_dph") - b0 - v
        if np.count_nonzero(np.diff(m)) < 2:
            return None
        target = (K * sd["bias_dph"]) ** 2 * len(m)
        a2, a1, a0 = m @ m, 2 * (m @ v), v @ v - target
        disc = a1 ** 2 - 4 * a2 * a0
        roots = [(-a1 + sq * math.sqrt(disc)) / (2 * a2) for sq in (1, -1)]
        pr["step_dph"] = float(max(roots) if sign > 0 else min(roots))
    withfx = clean_outputs(g, schedule, effect)
    return withfx, ratios(g, base, withfx, sd)


def draw_effect(name, g, rng, targets):
    tg = targets[int(rng.integers(len(targets)))]
    pr = {}
    if name == "bias.mode_hop":
        pr["step_dph"] = 0.0
        pr["range_modes"] = float(round(rng.uniform(0.5, 0.8), 3))
        pr["mode_spacing_C"] = float(round(rng.uniform(18.0, 40.0), 2))
        if rng.uniform() < 0.5:
            pr["centre_C"] = float(round(rng.uniform(-10.0, 40.0), 2))
    return {"name": name, "target": tg, "parameters": pr}


def plausible(effect):
    bad = []
    for k, v in effect["parameters"].items():
        if k in PLAUSIBLE:
            lo, hi = PLAUSIBLE[k]
            if not (lo <= v <= hi):
                bad.append(k)
    if effect["name"] == "bias.mode_hop":
        if not (15.0 <= effect["parameters"]["mode_spacing_C"] <= 70.0):
            bad.append("mode_spacing_C")
    return bad


# --------------------------------------------------------------------------- one case
def case_id(case, seed):
    return f"{case}_s{seed:02d}"


def time_text(t):
    """A sample time as the CSV writes it: whole seconds as an integer."""
    return str(int(t)) if float(t).is_integer() else repr(float(t))


def csv_text(nominal, schedule, noisy):
    chans = [s["ch"] for s in nominal["sensors"]]
    lines = ["# tests/heldout blind test data (%g s samples, zero input rate)" % DT,
             "run,t_s,T_amb," + ",".join(chans) + ",bias_dph"]
    for run in schedule:
        o = noisy[run["id"]]
        cols = [o[c] for c in chans]
        b = o["bias_dph"]
        for k in range(len(run["t"])):
            temps = ",".join(f"{c[k]:.4f}" for c in cols)
            lines.append(f"{run['id']},{time_text(run['t'][k])},{run['Tamb'][k]:.4f},{temps},"
                         f"{b[k]:.6f}")
    return "\n".join(lines) + "\n"


def generate(case, seed):
    """One blind case.  case: 'null' or an effect name of EFFECTS.  Returns a dict with
    'id', 'csv' (text), 'nominal' (text) and 'truth' (dict)."""
    if case != "null" and case not in EFFECTS:
        raise ValueError(f"unknown case {case!r}")
    ss = np.random.SeedSequence([int(seed), zlib.crc32(case.encode())])
    streams = ss.spawn(5)
    r_sched, r_gyro, r_fx, r_noise, r_mc = [np.random.default_rng(s) for s in streams]
    nominal = load_gyro(NOMINAL_PATH)
    with open(NOMINAL_PATH, encoding="utf-8") as f:
        nominal_text = f.read()
    true_g, drawn = perturb(nominal, r_gyro)
    schedule = make_schedule(r_sched)
    terms = instability_terms(true_g["noise"])
    effect = None
    notes = []
    if case == "null":
        base = clean_outputs(true_g, schedule, None)
        sd = noise_100s(true_g, base, r_mc, terms)
        final = base
        size = None
    else:
        K = K_RULE.get(case, K_DEFAULT)
        targets = list(TARGETS[case])
        # stratified: one random order of the targets per effect (independent of the seed);
        # seed s takes the s-th target of it (cycling), so seeds 1..n cover n distinct targets.
        order = list(np.random.default_rng(zlib.crc32(("targets:" + case).encode()))
                     .permutation(len(targets)))
        result = None
        for attempt in range(20):
            pick = order[(int(seed) - 1 + attempt) % len(targets)]
            eff = draw_effect(case, true_g, r_fx, [targets[pick]])
            g_use = true_g
            if case == "bias.mode_hop":
                # the true cavity expands so that one mode is the effect's spacing apart
                g_use = copy.deepcopy(true_g)
                b = g_use["bias"]
                b["alpha"] = b["lam"] / (b["L"] * eff["parameters"]["mode_spacing_C"])
            base = clean_outputs(g_use, schedule, None)
            sd = noise_100s(g_use, base, np.random.default_rng(r_mc.integers(2 ** 63)), terms)
            res = size_effect(g_use, schedule, base, sd, eff, K, r_fx)
            if res is None:
                notes.append(f"attempt {attempt}: {eff['target']} {eff['parameters']}: "
                             "no size reaches K (or too few mode hops); redrawn")
                continue
            bad = plausible(eff)
            if bad:
                notes.append(f"attempt {attempt}: {eff['target']} needs {bad} outside the "
                             f"catalog's plausible range ({eff['parameters']}); redrawn")
                continue
            result = (eff, g_use, base, sd, res)
            break
        if result is None:
            raise RuntimeError(f"{case} seed {seed}: no sensible target sized: {notes}")
        effect, true_g, base, sd, (final, rat) = result
        if case == "bias.mode_hop":
            drawn["bias.cte_per_C"] = true_g["bias"]["alpha"]
            notes.append("mode hop: each hop moves the bias by step_dph - plc_dph_per_wavelength = "
                         f"{effect['parameters']['step_dph'] - true_g['bias']['kplc']:.6g} deg/h "
                         "(the PLC travel resets by one wavelength); m counts hops since power-on; "
                         "the true cavity's cte is set so that lambda/(L cte) = mode_spacing_C")
        ch_max = max(rat, key=rat.get)
        diff = concat(final, ch_max) - concat(base, ch_max)
        size = {"K": K, "channel": ch_max, "measured_ratio": rat[ch_max],
                "ratios_by_channel": rat,
                "contribution_rms": float(math.sqrt(np.mean(diff ** 2))),
                "noise_100s_of_channel": sd[ch_max],
                "definition": "RMS over all samples of all runs of (noise-free output with the "
                              "effect - noise-free output without it) on the channel where "
                              "RMS/noise_100s is largest, divided by that channel's noise_100s"}
        if case == "bias.mode_hop":
            m = diff  # report where the hops happen
            size["hop_samples"] = int(np.count_nonzero(np.abs(np.diff(m)) > 1e-12))
    noisy = add_noise(true_g, final, r_noise, terms)
    csv = csv_text(nominal, schedule, noisy)
    # The same data without the effect: the same true gyro, schedule and noise draws (the noise
    # stream afresh), for the power analysis of score.py on data without the effect.
    csv_without = None
    if effect is not None:
        csv_without = csv_text(nominal, schedule, add_noise(true_g, base, np.random.default_rng(streams[3]), terms))
    # realised noise at 100 s in this data set (for the record)
    nb = int(round(BLOCK_S / DT))
    realised = {}
    for ch in channels(true_g):
        bm = np.concatenate([block_means(noisy[k][ch] - final[k][ch], nb) for k in final])
        realised[ch] = float(np.std(bm, ddof=1))
    truth = {
        "case": case_id(case, seed),
        "case_kind": case,
        "seed": int(seed),
        "effects": [] if effect is None else [effect],
        "size_rule": size,
        "noise_100s": sd,
        "noise_100s_definition": (
            "per channel: sd (ddof 1, about the record mean) of the means over consecutive whole "
            f"{nb * DT:g} s blocks ({nb} samples, from each run's power-on) of (noisy - noise-free) output, "
            f"rms over {MC_REPS} Monte Carlo realisations of the channel's full noise: "
            "temperatures white noise + rounding to the resolution (on the noise-free signal); "
            "bias ARW + bias-instability Gauss-Markov terms (+RRW) + turn-on constant + angle "
            "quantization"),
        "noise_100s_realised_in_this_data": realised,
        "bias_allan_deviation_100s_analytic_dph": allan_100s_bias(true_g["noise"], terms),
        "true_gyro_draws": drawn,
        "schedule": [{"run": r["id"], "duration_s": float(r["t"][-1]),
                      "ambient_points_s_C": [[float(a), float(b)] for a, b in r["points"]]}
                     for r in schedule],
        "notes": notes,
        "generator": "tests/heldout/gen.py",
    }
    if effect is not None:
        e = effect
        if e["name"] in ("bias.temperature_rate", "bias.hysteresis"):
            chs = [s["ch"] for s in nominal["sensors"] if s["node"] == e["target"]]
            truth["target_channel"] = chs[0] if chs else None
    return {"id": case_id(case, seed), "csv": csv, "csv_without_effect": csv_without, "nominal": nominal_text,
            "truth": truth}


def write_case(outdir, res):
    d = os.path.join(outdir, res["id"])
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, "data.csv"), "w") as f:
        f.write(res["csv"])
    if res["csv_without_effect"] is not None:
        with open(os.path.join(d, "data_without_effect.csv"), "w") as f:
            f.write(res["csv_without_effect"])
    with open(os.path.join(d, "nominal.toml"), "w") as f:
        f.write(res["nominal"])
    with open(os.path.join(d, "truth.json"), "w") as f:
        json.dump(res["truth"], f, indent=1)
        f.write("\n")
    return d


def all_cases():
    cases = [("null", s) for s in range(1, 11)]
    cases += [(e, s) for e in EFFECTS for s in (1, 2, 3)]
    return cases


# --------------------------------------------------------------------------- self-tests
def selftest():
    g = load_gyro()
    rng = np.random.default_rng(5)
    sched = make_schedule(rng)
    net = Network(g, [["anode", "cathode", 0.01]], [], {"T2": ("anode", 20.0)})
    X1, _ = net.simulate(sched[0])
    X2, _ = net.simulate(sched[0], force_ode=True)
    print("exact vs LSODA, linear network, max |dT| =", float(np.abs(X1 - X2).max()), "C")
    # radiation with tiny eA vs linear
    netr = Network(g, [], [["block", "cabinet", 1e-12]])
    X3, _ = netr.simulate(sched[1])
    X4, _ = Network(g).simulate(sched[1])
    print("LSODA (eA = 1e-12) vs exact, max |dT| =", float(np.abs(X3 - X4).max()), "C")
    # steady-state rises at 0.7 W (docs: 1.6 block, 2.6 anode, 2.2 cathode, 0.08 case)
    run = {"t": np.arange(0, 200000.0 + DT / 2, DT), "Tamb": None}
    run["Tamb"] = np.zeros(len(run["t"]))
    Xs, _ = Network(g).simulate(run)
    print("steady rise (block, anode, cathode, cabinet):",
          {nm: round(float(Xs[i, -1]), 3) for i, nm in enumerate(g["nodes"])})
    # flicker Allan deviation
    terms = instability_terms(g["noise"])
    taus = np.logspace(np.log10(30), np.log10(3e4), 7)
    ad = np.sqrt(sum(s ** 2 * gm_unit_avar(taus, Tc) for s, Tc in terms))
    print("flicker ADEV/(0.664 B) at", taus.round(0), ":", (ad / (0.664 * g["noise"]["B"])).round(3))
    # simulated ADEV of the full bias noise at 100 s vs analytic
    N = 100000
    x = bias_noisy(np.random.default_rng(1), np.zeros(N), g["noise"], DT, terms)
    bm = block_means(x, 10)
    adev = math.sqrt(0.5 * np.mean(np.diff(bm) ** 2))
    print("bias ADEV(100 s): simulated", round(adev, 5), "analytic",
          round(allan_100s_bias(g["noise"], terms), 5), "docs ~0.0064")
    w = bias_noisy(np.random.default_rng(2), np.zeros(N), dict(g["noise"], B=0.0, Q=0.0, turn_on=0.0),
                   DT, [])
    print("ARW 10 s sample sd", round(float(np.std(w)), 5), "expected", round(0.06 / math.sqrt(10), 5))


def _set_sample_period(dt):
    global DT
    DT = dt


def _generate_and_write(job):
    case, seed, out, dt = job
    _set_sample_period(dt)
    res = generate(case, seed)
    write_case(out, res)
    return res


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=None, help="output directory (one sub-directory per case)")
    ap.add_argument("--only", default=None, help="one case kind: null or an effect name")
    ap.add_argument("--seeds", default=None, help="comma-separated seeds (with --only)")
    ap.add_argument("--sample-period", type=float, default=10.0,
                    help="s (default 10); the size rule's blocks are the whole samples nearest 100 s")
    ap.add_argument("--jobs", type=int, default=1, help="cases generated at once (processes)")
    ap.add_argument("--selftest", action="store_true")
    a = ap.parse_args()
    _set_sample_period(a.sample_period)
    if not 0 < DT <= BLOCK_S:
        ap.error("--sample-period must be in (0, %g] s" % BLOCK_S)
    if a.selftest:
        selftest()
        return
    if not a.out:
        ap.error("--out DIR is required")
    out = os.path.abspath(a.out)
    cases = all_cases()
    if a.only:
        cases = [c for c in cases if c[0] == a.only]
    if a.seeds:
        want = {int(s) for s in a.seeds.split(",")}
        cases = [c for c in cases if c[1] in want] or [(a.only, s) for s in sorted(want)]
    os.makedirs(out, exist_ok=True)
    summary = []
    with multiprocessing.Pool(max(1, a.jobs)) as pool:
        for res in pool.imap(_generate_and_write, [(case, seed, out, DT) for case, seed in cases]):
            t = res["truth"]
            if t["effects"]:
                e = t["effects"][0]
                line = (f"{res['id']:32s} {e['target']:16s} "
                        + " ".join(f"{k}={v:.6g}" for k, v in e["parameters"].items())
                        + f"  K={t['size_rule']['K']} ratio={t['size_rule']['measured_ratio']:.4f}"
                        + f" on {t['size_rule']['channel']}")
            else:
                line = f"{res['id']:32s} none"
            print(line, flush=True)
            summary.append(line)
    with open(os.path.join(out, "SUMMARY.txt"), "w") as f:
        f.write("\n".join(summary) + "\n")


if __name__ == "__main__":
    main()
