#!/usr/bin/python3
"""refgen: an independent reference generator of ring-laser-gyro thermal data for rlgtherm.

Written WITHOUT reading any of rlgtherm's C++ source (sim/, model/, compensation/, cli/, the
C++ tests, tools/bench). The physics is derived here from docs/physics.md, the effect
catalog's names and ranges of scenarios/README.md (Effects) and the key table of scenarios/README.md; the file
formats from docs/data-format.md and scenarios/README.md. The reference gyro is our own
five-node gyro, not scenarios/gyros/default.toml. See tests/reference/README.md.

Model (every equation is written out in README.md):
  thermal   C_i dT_i/dt = sum_j G_ij (T_j - T_i) + G_ia (T_amb - T_i)
                          + sum_s share_si gain_s P_s (1 + g_s (T_n(s) - Tref_s))
                          + sum_r eA_r sigma ((T_j + 273.15)^4 - (T_i + 273.15)^4)
            linear case: exact matrix-exponential propagation with a first-order hold on the
            (piecewise-linear) ambient; with radiation: scipy solve_ivp (Radau), stepping on every
            input breakpoint.
  sensors   reading = (node through 0, 1 or 2 first-order lags) + offset + white noise,
            rounded to the resolution.
  bias      b0 + b1 dT + b2 dT^2 + (dI k_I + sum k_g (T_a - T_b)) (1 + c_T dT) + effects,
            dT = T_block - Tref; gyro noise: angle random walk (a Wiener angle), a first-order
            Gauss-Markov bias instability, a per-run turn-on constant, angle quantization.

CLI:  /usr/bin/python3 tests/reference/refgen.py CASE --seed N --sample-period S --out DIR
      [--strength X] [--noise-free] [--exact-ambient];   --list lists the cases.
"""

import argparse
import json
import math
import os
import sys
import tempfile

import numpy as np
from scipy.integrate import solve_ivp
from scipy.linalg import expm
from scipy.optimize import brentq

GENERATOR_VERSION = "refgen 1"
SIGMA_SB = 5.670374419e-8   # W/(m^2 K^4), CODATA 2018
KELVIN = 273.15
FINE_DT = 0.5               # s: the experiment's own time grid; every sample period is a multiple
ANGLE_DT = 0.25             # s: grid of the angle record (window edges of 0.5 s samples lie on it)
SCALE_DT = 5.0              # s: grid used only to size an effect (100 s block means; see scale_effect)
NOISE_REF_PERIOD = 1.0      # s: the strength's noise is that of 1 s samples, whatever --sample-period
SCORE_BLOCK = 100.0         # s: "the 100 s noise RMS"

# --------------------------------------------------------------------------------------------
# The reference gyro. [P] = docs/physics.md, [est] = our estimate.
# A five-node quadrangular HeNe gyro: Zerodur block, the two anodes lumped with the bore region
# around them, an aluminium cathode, a dither/mount assembly and an aluminium housing. Sensors
# on block (T1), anode (T2) and housing (T3); cathode and mount are not instrumented.


def reference_gyro():
    """The true gyro of every case (a fresh dict; the caller may change it)."""
    return {
        "name": "refgen-5node",
        "nodes": [
            # [P] Zerodur 2.53 g/cm3, c_p 0.82 J/(g K); a 0.46 kg block -> 380 J/K (P: 250-410)
            {"name": "block", "C": 380.0},
            # [est] two anodes (~30 g metal) and ~110 g of Zerodur around their bores
            {"name": "anode", "C": 120.0},
            # [est] ~85 g aluminium cathode, c_p 0.9 J/(g K)
            {"name": "cathode", "C": 75.0},
            # [est] dither spring, mount ring and screws, ~1 kg steel/aluminium: the slower
            # mount constant of P ("the mount/cabinet adds a slower ~1 h constant")
            {"name": "mount", "C": 900.0},
            # [est] ~2.1 kg aluminium housing
            {"name": "housing", "C": 1900.0},
        ],
        "links": [
            # [est] Zerodur k = 1.46 W/(m K) [P] over a few cm of bore wall: tau ~ 10 min
            ["anode", "block", 0.20],
            ["cathode", "block", 0.35],      # [est] large indium-sealed cathode flange
            ["block", "mount", 0.80],        # [est] dither hub clamp
            ["mount", "housing", 0.50],      # [est] mount ring bolted into the housing
            ["housing", "ambient", 6.0],     # [est] fixture plate + chamber air: housing follows in ~5 min
            ["block", "ambient", 0.025],     # [est] radiation/convection through case openings
            ["cathode", "housing", 0.015],   # [est] high-voltage lead and potting
        ],
        "radiation": [],
        "sources": [
            # [P] discharge 0.5-1.5 W (0.15-1 mA per leg at a few hundred V); the cathode fall
            # dissipates much of it near the cathode [P]. gain 0.97: ~3 % leaves as light and
            # through the leads [est].
            {"name": "discharge", "power_W": 0.8, "gain": 0.97, "logged": True,
             "shares": {"anode": 0.45, "cathode": 0.40, "block": 0.15}},
            # [est] dither drive losses in the spring and the block hub
            {"name": "dither", "power_W": 0.15, "gain": 1.0, "logged": False,
             "shares": {"mount": 0.7, "block": 0.3}},
        ],
        "sensors": {
            # [est] platinum sensors read by a 20-bit ADC: 2 mK white, 1 mK steps
            "T1": {"node": "block", "noise_C": 0.002, "resolution_C": 0.001},
            "T2": {"node": "anode", "noise_C": 0.002, "resolution_C": 0.001},
            "T3": {"node": "housing", "noise_C": 0.002, "resolution_C": 0.001},
        },
        "ambient_sensor": {"noise_C": 0.002, "resolution_C": 0.001},  # chamber sensor, same kind
        "bias": {
            "node": "block", "reference_C": 20.0,
            # [P] run-mean bias of the seed paper 0.63-1.42 deg/h; ours a different gyro [est]
            "b0_dph": 0.55, "b1_dph_per_C": 0.004, "b2_dph_per_C2": 6.0e-5,
            # [P] Aronowitz & Lim: 0.0066 deg/h per mA of leg-current imbalance
            "langmuir_current_imbalance_mA": 0.02, "langmuir_dph_per_mA": 0.0066,
            # 0: the docs leave open whether the gradient terms scale by (1 + c_T dT) (README)
            "langmuir_temperature_coeff_per_C": 0.0,
            # [P] 4.4 deg/h per cm/s of flow imbalance; 1 degC of anode-block gradient taken to
            # change it by 0.08 cm/s [est] -> 0.35 deg/h/degC
            "langmuir_gradient": [["anode", "block", 0.35]],
            # [P] 632.8 nm; Zerodur class 2 CTE up to 0.1 ppm/K [P]; a 32 cm path [est]:
            # one mode per lambda/(L alpha) = 22 K of block travel (P: 15-70 K)
            "path_length_m": 0.32, "cte_per_C": 9.0e-8, "wavelength_m": 632.8e-9,
            # 0: the docs do not say where the path-length-control travel is counted from (README)
            "plc_dph_per_wavelength": 0.0,
        },
        "noise": {
            # [P] navigation grade: ARW ~0.002 deg/rt-h (SIGI); ours slightly better [est]
            "arw_deg_per_sqrt_h": 0.0015,
            # [P] SIGI: bias instability 0.0035 deg/h, first-order Gauss-Markov, tau 3600 s
            "bias_instability_dph": 0.004, "gauss_markov_time_s": 3600.0,
            "quantization_arcsec": 0.005,     # [est] interpolated fringe counter
            "turn_on_sigma_dph": 0.002,       # [P] SIGI turn-on 0.001 deg/h; ours 2x [est]
        },
        # [est] 1 sigma of heat capacities, conductances, powers and gains across builds
        "relative_uncertainty": 0.06,
    }


def mode_spacing_C(gyro):
    b = gyro["bias"]
    return b["wavelength_m"] / (b["path_length_m"] * b["cte_per_C"])


# --------------------------------------------------------------------------------------------
# Runs: a ramp, steps, a dwell with a discharge-power step, a cool-then-warm cycle; power-on
# after a soak at the starting ambient (every node at T_amb(0)). Breakpoints on whole minutes so
# that every supported sample period (0.5, 1, 10, 60 s) samples them.

RUNS = [
    {"id": "ramp15to50", "duration_s": 9000.0,       # 0.5 degC/min: long block travel (mode hops)
     "ambient": [[0, 15], [1800, 15], [6000, 50], [9000, 50]]},
    {"id": "steps25-40", "duration_s": 9000.0,       # fast chamber steps (5 degC/min): transients
     "ambient": [[0, 25], [2400, 25], [2580, 40], [5400, 40], [5580, 25], [9000, 25]]},
    {"id": "dwell5-power", "duration_s": 9000.0,     # warm-up at 5 degC, then more discharge power
     "ambient": [[0, 5], [9000, 5]],
     "power": {"discharge": [[0, 0.8], [5400, 1.05]]}},
    {"id": "cycle35-10-35", "duration_s": 9000.0,    # cool then warm: heating/cooling asymmetry
     "ambient": [[0, 35], [1800, 35], [3840, 10], [5640, 10], [7680, 35], [9000, 35]]},
]


def run_power(run, source, t):
    """Commanded power of a source at times t (piecewise constant, right-continuous)."""
    prof = run.get("power", {}).get(source["name"])
    if prof is None:
        return np.full(np.shape(t), source["power_W"], dtype=float)
    times = np.array([p[0] for p in prof], dtype=float)
    vals = np.array([p[1] for p in prof], dtype=float)
    idx = np.searchsorted(times, t, side="right") - 1
    return vals[np.clip(idx, 0, None)]


def run_ambient(run, t):
    pts = np.array(run["ambient"], dtype=float)
    return np.interp(t, pts[:, 0], pts[:, 1])


def run_breakpoints(run):
    bps = {float(p[0]) for p in run["ambient"]}
    for prof in run.get("power", {}).values():
        bps |= {float(p[0]) for p in prof}
    return sorted(b for b in bps if 0.0 < b < run["duration_s"])


# --------------------------------------------------------------------------------------------
# Effects. Each is a dict {"name", "target", "parameters"}; catalog names where the form is the
# catalog's as scenarios/README.md describes it, "near.*" forms otherwise.


def apply_thermal_effects(gyro, effects):
    """A copy of the gyro with thermal and sensor effects built into its network description."""
    g = json.loads(json.dumps(gyro))
    g.setdefault("power_drift", [])
    for e in effects:
        n, p = e["name"], e["parameters"]
        if n == "thermal.missing_mass":
            a, b = e["target"].split("-")
            hidden = "hidden_mass%d" % len([x for x in g["nodes"] if x["name"].startswith("hidden")])
            g["nodes"].append({"name": hidden, "C": p["heat_capacity_J_per_K"]})
            g["links"].append([a, hidden, p["conductance_W_per_K"]])
            g["links"].append([hidden, b, p["conductance_W_per_K"]])
        elif n == "thermal.missing_link":
            a, b = e["target"].split("-")
            g["links"].append([a, b, p["conductance_W_per_K"]])
        elif n == "thermal.radiation":
            a, b = e["target"].split("-")
            g["radiation"].append([a, b, p["emissivity_area_m2"]])
        elif n == "thermal.power_drift":
            g["power_drift"].append({"node": e["target"], "g_per_C": p["g_per_C"],
                                     "reference_C": p.get("reference_C", 20.0)})
        elif n == "sensor.lag":
            g["sensors"][e["target"]].setdefault("lags_s", []).append(p["time_constant_s"])
        elif n == "sensor.offset":
            s = g["sensors"][e["target"]]
            s["offset_C"] = s.get("offset_C", 0.0) + p["offset_C"]
    return g


class Network:
    """The linear(ised) network of a gyro: state = node temperatures, then sensor-lag states.

    dx/dt = A(P) x + B(P) [T_amb, 1] + radiation(x); A and B depend on the commanded powers
    only through thermal.power_drift (a source whose power depends on a node temperature)."""

    def __init__(self, gyro):
        self.gyro = gyro
        self.names = [n["name"] for n in gyro["nodes"]]
        idx = {n: i for i, n in enumerate(self.names)}
        self.idx = idx
        nn = len(self.names)
        self.C = np.array([n["C"] for n in gyro["nodes"]], dtype=float)
        K = np.zeros((nn, nn))   # conductance Laplacian (node-node links)
        Ga = np.zeros(nn)        # conductance to ambient
        for a, b, G in gyro["links"]:
            if b == "ambient" or a == "ambient":
                Ga[idx[a if b == "ambient" else b]] += G
            else:
                i, j = idx[a], idx[b]
                K[i, i] += G
                K[j, j] += G
                K[i, j] -= G
                K[j, i] -= G
        self.K, self.Ga = K, Ga
        self.rad = []
        for a, b, eA in gyro.get("radiation", []):
            ia = idx[a]
            ib = None if b == "ambient" else idx[b]
            self.rad.append((ia, ib, eA))
        # per source: share vector, gain, drift (node index, g, Tref) or None
        self.sources = []
        drifts = {d["node"]: d for d in gyro.get("power_drift", [])}
        for s in gyro["sources"]:
            share = np.zeros(nn)
            for node, f in s["shares"].items():
                share[idx[node]] += f
            drift = None
            for node in s["shares"]:
                if node in drifts:
                    d = drifts[node]
                    drift = (idx[node], d["g_per_C"], d["reference_C"])
            self.sources.append((s, share, s.get("gain", 1.0), drift))
        # sensor lag chains
        self.lag_rows = []   # (input state index, tau) per lag state, in state order
        self.channel_state = {}
        k = nn
        for ch in sorted(gyro["sensors"]):
            sen = gyro["sensors"][ch]
            src = idx[sen["node"]]
            for tau in sen.get("lags_s", []):
                self.lag_rows.append((src, tau))
                src = k
                k += 1
            self.channel_state[ch] = src
        self.n_nodes = nn
        self.n = k

    def matrices(self, powers):
        """A, B for commanded source powers `powers` (one value per source)."""
        nn, n = self.n_nodes, self.n
        A = np.zeros((n, n))
        B = np.zeros((n, 2))
        A[:nn, :nn] = -(self.K + np.diag(self.Ga))
        B[:nn, 0] = self.Ga
        for (s, share, gain, drift), P in zip(self.sources, powers):
            q = share * gain * P
            if drift is None:
                B[:nn, 1] += q
            else:
                j, g, tref = drift
                B[:nn, 1] += q * (1.0 - g * tref)
                A[:nn, j] += q * g
        A[:nn, :] /= self.C[:, None]
        B[:nn, :] /= self.C[:, None]
        for r, (src, tau) in enumerate(self.lag_rows):
            A[self.n_nodes + r, src] += 1.0 / tau
            A[self.n_nodes + r, self.n_nodes + r] -= 1.0 / tau
        return A, B

    def radiation(self, x, T_amb):
        """Net radiative heat flow into each node divided by C (dT/dt contribution)."""
        out = np.zeros(self.n)
        for ia, ib, eA in self.rad:
            Ta = x[ia] + KELVIN
            Tb = (T_amb if ib is None else x[ib]) + KELVIN
            q = eA * SIGMA_SB * (Tb ** 4 - Ta ** 4)
            out[ia] += q / self.C[ia]
            if ib is not None:
                out[ib] -= q / self.C[ib]
        return out


def simulate_run(net, run, dt=FINE_DT, method="auto"):
    """Noise-free simulation of one run on the grid 0, dt, ..., duration.

    Returns dict: t, x (states, len(t) x n), xdot (right derivative), T_amb, powers (per source).
    method: "expm" (exact for a linear network), "ivp" (Radau), "auto" (expm unless radiation)."""
    T = run["duration_s"]
    nsteps = int(round(T / dt))
    t = np.arange(nsteps + 1) * dt
    for bp in run_breakpoints(run):
        if abs(bp / dt - round(bp / dt)) > 1e-9:
            raise ValueError("breakpoint %g s of run %s is not on the %g s grid" % (bp, run["id"], dt))
    amb = run_ambient(run, t)
    P = np.stack([run_power(run, s, t) for (s, _, _, _) in net.sources], axis=1)
    x0 = np.full(net.n, amb[0])
    if method == "auto":
        method = "ivp" if net.rad else "expm"
    x = np.empty((nsteps + 1, net.n))
    x[0] = x0
    cache = {}
    if method == "expm":
        n, m = net.n, 2
        u = np.stack([amb, np.ones_like(amb)], axis=1)
        for k0, k1 in _segments(P):
            key = tuple(P[k0])
            if key not in cache:
                A, B = net.matrices(P[k0])
                M = np.zeros((n + 2 * m, n + 2 * m))
                M[:n, :n] = A
                M[:n, n:n + m] = B
                M[n:n + m, n + m:] = np.eye(m)
                E = expm(M * dt)
                cache[key] = (A, B, E[:n, :n], E[:n, n:n + m], E[:n, n + m:])
            A, B, Phi, Gu, Gv = cache[key]
            # x_{k+1} = Phi x_k + Gu u_k + Gv (u_{k+1} - u_k)/dt : exact for u linear in the step
            kk = np.arange(k0, k1)
            c = u[kk] @ Gu.T + ((u[kk + 1] - u[kk]) / dt) @ Gv.T
            xk = x[k0]
            for j, k in enumerate(kk):
                xk = Phi @ xk + c[j]
                x[k + 1] = xk
    elif method == "ivp":
        bps = [0.0] + run_breakpoints(run) + [T]
        for a, b in zip(bps[:-1], bps[1:]):
            ka, kb = int(round(a / dt)), int(round(b / dt))
            A, B = net.matrices(P[ka])
            slope_amb = (run_ambient(run, b) - run_ambient(run, a)) / (b - a)
            amb_a = run_ambient(run, a)

            def rhs(tt, xx, A=A, B=B, a=a, amb_a=amb_a, slope=slope_amb):
                Ta = amb_a + slope * (tt - a)
                return A @ xx + B[:, 0] * Ta + B[:, 1] + net.radiation(xx, Ta)

            def jac(tt, xx, A=A, a=a, amb_a=amb_a, slope=slope_amb):
                J = A.copy()
                for ia, ib, eA in net.rad:
                    d = 4.0 * eA * SIGMA_SB
                    J[ia, ia] -= d * (xx[ia] + KELVIN) ** 3 / net.C[ia]
                    if ib is not None:
                        J[ia, ib] += d * (xx[ib] + KELVIN) ** 3 / net.C[ia]
                        J[ib, ib] -= d * (xx[ib] + KELVIN) ** 3 / net.C[ib]
                        J[ib, ia] += d * (xx[ia] + KELVIN) ** 3 / net.C[ib]
                return J

            sol = solve_ivp(rhs, (a, b), x[ka], method="Radau", jac=jac, rtol=1e-10,
                            atol=1e-10, t_eval=t[ka:kb + 1])
            if not sol.success:
                raise ArithmeticError("solve_ivp failed in run %s: %s" % (run["id"], sol.message))
            x[ka:kb + 1] = sol.y.T
    else:
        raise ValueError(method)
    # right derivative at every grid point (the power of the step that starts there)
    xdot = np.empty_like(x)
    for k0, k1 in _segments(P, include_last=True):
        A, B = net.matrices(P[k0])
        sl = slice(k0, k1)
        xdot[sl] = x[sl] @ A.T + np.outer(amb[sl], B[:, 0]) + B[:, 1]
        if net.rad:
            for k in range(k0, k1):
                xdot[k] += net.radiation(x[k], amb[k])
    return {"t": t, "x": x, "xdot": xdot, "T_amb": amb, "P": P}


def _segments(P, include_last=False):
    """[k0, k1) index ranges of steps k -> k+1 with constant power (the power at k)."""
    n = P.shape[0] if include_last else P.shape[0] - 1
    if n <= 0:
        return []
    # Inside a segment every row equals its first, so a row differs from the segment's first
    # exactly where it differs from the row before it: one vectorised comparison.
    starts = (np.flatnonzero(np.any(P[1:n] != P[:n - 1], axis=1)) + 1).tolist()
    bounds = [0] + starts + [n]
    return list(zip(bounds[:-1], bounds[1:]))


# --------------------------------------------------------------------------------------------
# Bias


def deterministic_bias(gyro, net, sim, bias_effects):
    """Bias in deg/h on the simulation grid, without noise."""
    b = gyro["bias"]
    x = sim["x"]
    Tb = x[:, net.idx[b["node"]]]
    dT = Tb - b["reference_C"]
    flow = b["langmuir_current_imbalance_mA"] * b["langmuir_dph_per_mA"]
    flow = flow + sum(k * (x[:, net.idx[a]] - x[:, net.idx[c]]) for a, c, k in b["langmuir_gradient"])
    bias = (b["b0_dph"] + b["b1_dph_per_C"] * dT + b["b2_dph_per_C2"] * dT ** 2
            + flow * (1.0 + b["langmuir_temperature_coeff_per_C"] * dT))
    travel = b["path_length_m"] * b["cte_per_C"] * dT / b["wavelength_m"]
    bias = bias + b["plc_dph_per_wavelength"] * travel
    for e in bias_effects:
        bias = bias + bias_effect_term(gyro, net, sim, e)
    return bias


def node_of(net, gyro, target):
    """A target naming a node, or a channel meaning the node it sits on."""
    if target in net.idx:
        return net.idx[target]
    return net.idx[gyro["sensors"][target]["node"]]


def bias_effect_term(gyro, net, sim, e):
    n, p, x = e["name"], e["parameters"], sim["x"]
    if n == "bias.temperature_rate":
        j = node_of(net, gyro, e["target"])
        return p["k_dph_per_C_per_min"] * 60.0 * sim["xdot"][:, j]
    if n == "bias.gradient":
        a, c = e["target"].split("-")
        return p["k_dph_per_C"] * (x[:, node_of(net, gyro, a)] - x[:, node_of(net, gyro, c)])
    if n == "bias.hysteresis":
        T = x[:, node_of(net, gyro, e["target"])]
        d = np.diff(T)
        inc = np.where(d > 0, p["k_heating_dph_per_C"], p["k_cooling_dph_per_C"]) * d
        return np.concatenate([[0.0], np.cumsum(inc)])
    if n == "bias.mode_hop":
        # Path-length control centred on a mode at power-on; its travel in modes is
        # (T - T(0)) / spacing minus the resets so far; one reset when |travel| > range.
        T = x[:, node_of(net, gyro, e["target"])]
        s = p.get("mode_spacing_C", mode_spacing_C(gyro))
        rng = p.get("range_modes", 0.6)
        rel = (T - T[0]) / s
        nres = np.zeros(len(T))
        m = 0
        for k in range(len(T)):
            while rel[k] - m > rng:
                m += 1
            while rel[k] - m < -rng:
                m -= 1
            nres[k] = m
        return p["step_dph"] * nres
    if n == "near.reversible_hops":
        # No path-length control state: the bias is a staircase of the absolute block
        # temperature, the same on the way up and down (no hysteresis).
        T = x[:, node_of(net, gyro, e["target"])]
        return p["step_dph"] * np.floor((T - p["first_edge_C"]) / p["spacing_C"])
    raise ValueError("not a bias effect: " + n)


BIAS_EFFECTS = {"bias.temperature_rate", "bias.gradient", "bias.hysteresis", "bias.mode_hop",
                "near.reversible_hops"}


def channel_truth(net, sim, gyro):
    """Noise-free sensor readings (lags and offsets included), per channel."""
    out = {}
    for ch, sen in gyro["sensors"].items():
        out[ch] = sim["x"][:, net.channel_state[ch]] + sen.get("offset_C", 0.0)
    return out


def simulate_truth(gyro, effects, runs=RUNS, dt=FINE_DT):
    """Noise-free truth per run: channels, bias, ambient, commanded powers, states."""
    g = apply_thermal_effects(gyro, effects)
    net = Network(g)
    bias_eff = [e for e in effects if e["name"] in BIAS_EFFECTS]
    out = []
    for run in runs:
        sim = simulate_run(net, run, dt)
        out.append({"run": run, "sim": sim, "channels": channel_truth(net, sim, g),
                    "bias": deterministic_bias(g, net, sim, bias_eff), "net": net, "gyro": g})
    return out


# --------------------------------------------------------------------------------------------
# Noise and its 100 s RMS (the unit of --strength)


def sigma100(gyro):
    """RMS of the noise of 100 s means, for 1 s samples (NOISE_REF_PERIOD), per channel and bias.

    Temperature: readings independent, variance noise^2 + resolution^2/12 (uniform rounding
    error), averaged over 100 readings.  Bias: ARW N gives sigma(tau) = 60 N / sqrt(tau_s) deg/h;
    the Gauss-Markov instability contributes its full variance B^2 (its one-hour correlation time
    leaves a 100 s mean nearly the process value); quantization and turn-on are left out (the
    first is q/100 arcsec/s = 5e-5 deg/h, the second a per-run constant any bias model absorbs)."""
    nblk = SCORE_BLOCK / NOISE_REF_PERIOD
    out = {}
    for ch, s in gyro["sensors"].items():
        out[ch] = math.sqrt(s["noise_C"] ** 2 + s["resolution_C"] ** 2 / 12.0) / math.sqrt(nblk)
    nz = gyro["noise"]
    out["bias_dph"] = math.sqrt((60.0 * nz["arw_deg_per_sqrt_h"]) ** 2 / SCORE_BLOCK
                                + nz["bias_instability_dph"] ** 2)
    return out


def block_means(t, y, block=SCORE_BLOCK):
    """Means of y over whole blocks [k block, (k+1) block) of a uniform grid."""
    dt = t[1] - t[0]
    per = int(round(block / dt))
    nb = (len(y) - 1) // per
    return y[: nb * per].reshape(nb, per).mean(axis=1)


# --------------------------------------------------------------------------------------------
# Cases


def _e(name, target, **params):
    return {"name": name, "target": target, "parameters": params}


# Effect shapes at scale s (s is solved for so that the signature is `strength` noise RMS).
SHAPES = {
    "thermal.missing_mass": ("thermal", lambda s: [_e(
        "thermal.missing_mass", "block-housing", heat_capacity_J_per_K=200.0 * s,
        conductance_W_per_K=0.25 * s)]),
    "thermal.missing_link": ("thermal", lambda s: [_e(
        "thermal.missing_link", "anode-housing", conductance_W_per_K=s)]),
    "thermal.power_drift": ("thermal", lambda s: [_e(
        "thermal.power_drift", "cathode", g_per_C=s, reference_C=20.0)]),
    "thermal.radiation": ("thermal", lambda s: [_e(
        "thermal.radiation", "block-housing", emissivity_area_m2=s)]),
    "sensor.lag": ("thermal", lambda s: [_e("sensor.lag", "T1", time_constant_s=s)]),
    "sensor.offset": ("thermal", lambda s: [_e("sensor.offset", "T2", offset_C=s)]),
    "bias.temperature_rate": ("bias", lambda s: [_e(
        "bias.temperature_rate", "block", k_dph_per_C_per_min=s)]),
    "bias.gradient": ("bias", lambda s: [_e("bias.gradient", "block-housing", k_dph_per_C=s)]),
    "bias.hysteresis": ("bias", lambda s: [_e(
        "bias.hysteresis", "block", k_heating_dph_per_C=s / 2, k_cooling_dph_per_C=-s / 2)]),
    "bias.mode_hop": ("bias", lambda s: [_e(
        "bias.mode_hop", "block", step_dph=s, range_modes=0.6,
        mode_spacing_C=mode_spacing_C(reference_gyro()))]),
    "near.reversible_hops": ("bias", lambda s: [_e(
        "near.reversible_hops", "block", step_dph=s, spacing_C=13.0, first_edge_C=3.5)]),
    "near.double_lag": ("thermal", lambda s: [_e("sensor.lag", "T2", time_constant_s=s)]),
}

DOUBLE_LAG_KNOWN_S = 30.0   # the nominal's own lag on T2 in near.double_lag

CASES = {
    "none": "no hidden effect (the null case)",
    "thermal.missing_mass": "an uninstrumented 2-link mass between block and housing",
    "thermal.missing_link": "a conductance anode-housing the nominal lacks",
    "thermal.power_drift": "discharge power P0 (1 + g (T_cathode - 20))",
    "thermal.radiation": "radiative exchange block-housing",
    "sensor.lag": "first-order lag of channel T1",
    "sensor.offset": "constant offset of channel T2",
    "bias.temperature_rate": "bias + k dT_block/dt",
    "bias.gradient": "bias + k (T_block - T_housing)",
    "bias.hysteresis": "bias accumulates +k/2 dT heating, -k/2 dT cooling (block)",
    "bias.mode_hop": "PLC resets by one mode past +-0.6 modes; bias steps per reset",
    "near.reversible_hops": "bias staircase of absolute block temperature, 13 degC steps, "
                            "no hysteresis (the nominal's lambda/(L alpha) is 22 degC)",
    "near.mass_and_link": "a missing mass block-housing AND a missing link anode-housing",
    "near.double_lag": "a second lag on T2, whose 30 s lag the nominal already has",
    "near.heavy_nominal": "no hidden effect; the nominal's heat capacities are all 30 % high",
}

# What a diagnosis could fairly answer for each case (for survey tables; not used to generate).
EXPECTED = {
    "near.reversible_hops": "bias.mode_hop (nearest catalog form) or a stand-in",
    "near.mass_and_link": "thermal.missing_mass and thermal.missing_link (two steps)",
    "near.double_lag": "sensor.lag T2",
    "near.heavy_nominal": "none (with prior conflicts on the C knobs)",
}


THERMAL_KNOB_STEP = 1e-4   # relative step of the central differences of the knob Jacobian


def thermal_knobs(gyro):
    """The knobs a calibration of the nominal network moves: every heat capacity, conductance
    and source gain (log units)."""
    return (["C:" + n["name"] for n in gyro["nodes"]]
            + ["G:%d" % i for i in range(len(gyro["links"]))]
            + ["gain:" + s["name"] for s in gyro["sources"]])


def scaled_gyro(gyro, knob, factor):
    g = json.loads(json.dumps(gyro))
    kind, name = knob.split(":")
    if kind == "C":
        next(n for n in g["nodes"] if n["name"] == name)["C"] *= factor
    elif kind == "G":
        g["links"][int(name)][2] *= factor
    else:
        next(s for s in g["sources"] if s["name"] == name)["gain"] *= factor
    return g


def thermal_vector(truth):
    """100 s block means of every temperature channel of every run, stacked (channel-major)."""
    chans = sorted(truth[0]["channels"])
    return np.concatenate([np.concatenate([block_means(tr["sim"]["t"], tr["channels"][c])
                                           for tr in truth]) for c in chans]), chans


def bias_regressors(truth):
    """100 s block means of the nominal bias model's regressors, pooled over runs (shared
    coefficients): 1, dT, dT^2 of the bias node and each Langmuir gradient (T_a - T_b)."""
    cols = []
    for tr in truth:
        g = tr["gyro"]
        b, net, x, t = g["bias"], tr["net"], tr["sim"]["x"], tr["sim"]["t"]
        dT = x[:, net.idx[b["node"]]] - b["reference_C"]
        regs = [np.ones_like(dT), dT, dT ** 2]
        regs += [x[:, net.idx[a]] - x[:, net.idx[c]] for a, c, _ in b["langmuir_gradient"]]
        cols.append(np.stack([block_means(t, r) for r in regs], axis=1))
    return np.concatenate(cols)


def _orth_basis(J):
    """Orthonormal basis of the column space of J (SVD; directions below 1e-10 of the largest
    singular value are the exact degeneracies, e.g. the common scale of C, G and P)."""
    U, sv, _ = np.linalg.svd(J, full_matrices=False)
    return U[:, sv > 1e-10 * sv[0]]


class Sizer:
    """Sizes an effect: the RMS over every 100 s block of every run of the part of its noise-free
    signature (with effect - without) that the nominal model cannot take up, per channel, over
    that channel's 100 s noise RMS (sigma100); the largest over channels is the strength.
    "Cannot take up": the least-squares remainder after projecting the signature on
      thermal effects: the Jacobian of all temperature channels' block means with respect to
                       every knob of the calibration (log C, log G, log gain), at the truth,
                       channels jointly (all channels share the knobs);
      bias effects:    the nominal bias regressors (1, dT, dT^2, Langmuir gradients), pooled.
    This linearised calibration has no prior, so it takes up at least what a prior-bound
    calibration can; the raw (unprojected) strength is reported beside it."""

    def __init__(self, kind, base_effects):
        self.kind = kind
        self.base_effects = base_effects
        self.gyro = reference_gyro()
        self.sig = sigma100(self.gyro)
        self.without = simulate_truth(self.gyro, base_effects, dt=SCALE_DT)
        if kind == "thermal":
            y0, self.chans = thermal_vector(self.without)
            cols = []
            for knob in thermal_knobs(self.gyro):
                hi = simulate_truth(scaled_gyro(self.gyro, knob, math.exp(THERMAL_KNOB_STEP)),
                                    base_effects, dt=SCALE_DT)
                lo = simulate_truth(scaled_gyro(self.gyro, knob, math.exp(-THERMAL_KNOB_STEP)),
                                    base_effects, dt=SCALE_DT)
                cols.append((thermal_vector(hi)[0] - thermal_vector(lo)[0])
                            / (2 * THERMAL_KNOB_STEP))
            self.Q = _orth_basis(np.stack(cols, axis=1))
            self.nblk = len(y0) // len(self.chans)
        else:
            self.chans = ["bias_dph"]
            self.Q = _orth_basis(bias_regressors(self.without))
            self.nblk = self.Q.shape[0]

    def measure(self, effects):
        w = simulate_truth(self.gyro, self.base_effects + effects, dt=SCALE_DT)
        if self.kind == "thermal":
            d = thermal_vector(w)[0] - thermal_vector(self.without)[0]
        else:
            d = np.concatenate([block_means(a["sim"]["t"], a["bias"] - b["bias"])
                                for a, b in zip(w, self.without)])
        left = d - self.Q @ (self.Q.T @ d)
        out = {"left": {}, "raw": {}}
        for i, ch in enumerate(self.chans):
            sl = slice(i * self.nblk, (i + 1) * self.nblk)
            out["left"][ch] = float(np.sqrt(np.mean(left[sl] ** 2))) / self.sig[ch]
            out["raw"][ch] = float(np.sqrt(np.mean(d[sl] ** 2))) / self.sig[ch]
        ch = max(out["left"], key=out["left"].get)
        return out["left"][ch], ch, out


LINEAR_CASES = ("sensor.offset", "bias.temperature_rate", "bias.gradient", "bias.hysteresis",
                "bias.mode_hop", "near.reversible_hops")


def scale_effect(case, strength):
    """Effects of `case` sized to `strength` (see Sizer), on a 5 s grid with the true gyro, so
    the size depends on case and strength only, not on seed or sample period (100 s block means
    of a 5 s grid differ from the 0.5 s grid's by far less than the root finder's 1e-4 in log s).
    Returns (effects, report)."""
    kind, shape = SHAPES[case]
    base_effects = []
    if case == "near.double_lag":
        base_effects = [_e("sensor.lag", "T2", time_constant_s=DOUBLE_LAG_KNOWN_S)]
    sizer = Sizer(kind, base_effects)

    def ratio(s):
        return sizer.measure(shape(s))[0]

    if strength <= 0:
        s = 0.0
    elif case in LINEAR_CASES:
        # the signature is proportional to s (the hop pattern is fixed by the temperatures)
        s = strength / ratio(1.0)
    else:
        # monotone in s: bracket in log s, then Brent
        lo, hi = 1e-6, 1e-3
        while ratio(hi) < strength:
            lo, hi = hi, hi * 10.0
            if hi > 1e7:
                raise ArithmeticError("cannot reach strength %g for %s" % (strength, case))
        s = math.exp(brentq(lambda ls: math.log(ratio(math.exp(ls)) / strength),
                            math.log(lo), math.log(hi), xtol=1e-4))
    r, ch, detail = sizer.measure(shape(s)) if s > 0 else (0.0, None, {})
    return base_effects + shape(s), {"scale": s, "channel": ch, "achieved_strength": r,
                                     "sigma100": sizer.sig.get(ch),
                                     "strength_left_per_channel": detail.get("left"),
                                     "strength_raw_per_channel": detail.get("raw")}


def case_effects(case, strength):
    if case in ("none", "near.heavy_nominal"):
        return [], {"scale": None}
    if case == "near.mass_and_link":
        e1, r1 = scale_effect("thermal.missing_mass", strength)
        e2, r2 = scale_effect("thermal.missing_link", strength)
        return e1 + e2, {"thermal.missing_mass": r1, "thermal.missing_link": r2}
    return scale_effect(case, strength)


# --------------------------------------------------------------------------------------------
# The nominal gyro: the reference gyro with its parameters drawn within the stated prior


def draw_nominal(gyro, rng, case):
    """Thermal knobs (C, G, source power and gain) times exp(sigma z), z ~ N(0,1) clipped to
    +-2 (within 2 prior sigma); bias coefficients times (1 + 0.25 z), z clipped to +-2 (the file's
    bias coefficients are a wide prior in rlgtherm; 25 % is a part-to-part spread [est])."""
    sigma = gyro["relative_uncertainty"]
    nom = json.loads(json.dumps(gyro))
    factors = {}

    def z():
        return float(np.clip(rng.standard_normal(), -2.0, 2.0))

    for n in nom["nodes"]:
        f = math.exp(sigma * z())
        if case == "near.heavy_nominal":
            f = 1.30
        n["C"] *= f
        factors["C:" + n["name"]] = f
    for lk in nom["links"]:
        f = math.exp(sigma * z())
        lk[2] *= f
        factors["G:%s-%s" % (lk[0], lk[1])] = f
    for s in nom["sources"]:
        f = math.exp(sigma * z())
        s["power_W"] *= f
        factors["P:" + s["name"]] = f
        f = math.exp(sigma * z())
        s["gain"] *= f
        factors["gain:" + s["name"]] = f
    b = nom["bias"]
    for key in ("b0_dph", "b1_dph_per_C", "b2_dph_per_C2"):
        f = 1.0 + 0.25 * z()
        b[key] *= f
        factors[key] = f
    for lg in b["langmuir_gradient"]:
        f = 1.0 + 0.25 * z()
        lg[2] *= f
        factors["langmuir_gradient:%s-%s" % (lg[0], lg[1])] = f
    return nom, factors


def fmt_num(v):
    """Shortest decimal that reads back to the same double (TOML and JSON)."""
    r = repr(float(v))
    return r if ("e" in r or "." in r or "inf" in r or "nan" in r) else r + ".0"


def nominal_toml(nom, effects_in_nominal, header):
    L = ["# " + line for line in header]
    L.append('name = "%s-nominal"' % nom["name"])
    for n in nom["nodes"]:
        L += ["", "[[nodes]]", 'name = "%s"' % n["name"],
              "heat_capacity_J_per_K = %s" % fmt_num(n["C"])]
    for a, b, G in nom["links"]:
        L += ["", "[[links]]", 'between = ["%s", "%s"]' % (a, b),
              "conductance_W_per_K = %s" % fmt_num(G)]
    for a, b, eA in nom.get("radiation", []):
        L += ["", "[[radiation]]", 'between = ["%s", "%s"]' % (a, b),
              "emissivity_area_m2 = %s" % fmt_num(eA)]
    for s in nom["sources"]:
        shares = ", ".join("%s = %s" % (k, fmt_num(v)) for k, v in s["shares"].items())
        L += ["", "[[sources]]", 'name = "%s"' % s["name"], "power_W = %s" % fmt_num(s["power_W"]),
              "gain = %s" % fmt_num(s["gain"]), "shares = { %s }" % shares]
        if s["logged"]:
            L[-1] += "   # logged as P_%s_W in data.csv" % s["name"]
    for ch in sorted(nom["sensors"]):
        sen = nom["sensors"][ch]
        L += ["", "[sensors.%s]" % ch, 'node = "%s"' % sen["node"],
              "noise_C = %s" % fmt_num(sen["noise_C"]),
              "resolution_C = %s" % fmt_num(sen["resolution_C"])]
    b = nom["bias"]
    L += ["", "[bias]", 'node = "%s"' % b["node"]]
    for key in ("reference_C", "b0_dph", "b1_dph_per_C", "b2_dph_per_C2",
                "langmuir_current_imbalance_mA", "langmuir_dph_per_mA",
                "langmuir_temperature_coeff_per_C", "path_length_m", "cte_per_C",
                "wavelength_m", "plc_dph_per_wavelength"):
        L.append("%s = %s" % (key, fmt_num(b[key])))
    for a, c, k in b["langmuir_gradient"]:
        L += ["", "[[bias.langmuir_gradient]]", 'between = ["%s", "%s"]' % (a, c),
              "k_dph_per_C = %s" % fmt_num(k)]
    nz = nom["noise"]
    L += ["", "[noise]",
          "arw_deg_per_sqrt_h = %s" % fmt_num(nz["arw_deg_per_sqrt_h"]),
          "bias_instability_dph = %s" % fmt_num(nz["bias_instability_dph"]),
          'instability_model = "gauss_markov"',
          "gauss_markov_time_s = %s" % fmt_num(nz["gauss_markov_time_s"]),
          "rrw_deg_per_h_per_sqrt_h = 0.0",
          "quantization_arcsec = %s" % fmt_num(nz["quantization_arcsec"]),
          "turn_on_sigma_dph = %s" % fmt_num(nz["turn_on_sigma_dph"])]
    L += ["", "[calibration]", "relative_uncertainty = %s" % fmt_num(nom["relative_uncertainty"])]
    for e in effects_in_nominal:
        L += ["", "[[effects]]", 'name = "%s"' % e["name"], 'target = "%s"' % e["target"]]
        for k, v in e["parameters"].items():
            L.append("%s = %s" % (k, fmt_num(v)))
    return "\n".join(L) + "\n"


# --------------------------------------------------------------------------------------------
# Sampling with noise and writing the tidy CSV


def _run_rng(seed, purpose, run_index):
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence([seed, purpose, run_index])))


def fmt_time(t):
    r = repr(float(t))
    return r[:-2] if r.endswith(".0") else r


def sample_run(gyro, truth, run_index, seed, period, noise=True, exact_ambient=False):
    """Samples of one run at `period`. The noise realisation belongs to the experiment (seed,
    run) on the 0.5 s / 0.25 s grids, so a coarser period reads the same experiment."""
    sim, run = truth["sim"], truth["run"]
    t_f = sim["t"]
    ratio = period / FINE_DT
    if abs(ratio - round(ratio)) > 1e-9 or ratio < 1:
        raise ValueError("sample period %g s is not a whole multiple of %g s" % (period, FINE_DT))
    step = int(round(ratio))
    K = (len(t_f) - 1) // step
    kf = np.arange(K + 1) * step
    t_s = t_f[kf]
    rng = _run_rng(seed, 2, run_index)   # sensors, 0.5 s grid
    rows = {}
    nf = len(t_f)
    for ch in sorted(gyro["sensors"]):
        sen = gyro["sensors"][ch]
        y = truth["channels"][ch].copy()
        w = rng.standard_normal(nf)
        if noise:
            y = y + sen["noise_C"] * w
            if sen["resolution_C"] > 0:
                y = sen["resolution_C"] * np.round(y / sen["resolution_C"])
        rows[ch] = y[kf]
    amb = truth["sim"]["T_amb"].copy()
    w = rng.standard_normal(nf)
    if noise and not exact_ambient:
        a = gyro["ambient_sensor"]
        amb = a["resolution_C"] * np.round((amb + a["noise_C"] * w) / a["resolution_C"])
    rows["T_amb"] = amb[kf]
    rows["bias_dph"] = sample_bias(gyro, truth["bias"], t_f, kf, seed, run_index, noise)
    for (s, _, _, _), j in zip(truth["net"].sources, range(sim["P"].shape[1])):
        if s["logged"]:
            rows["P_%s_W" % s["name"]] = sim["P"][kf, j]
    rows["t_s"] = t_s
    return rows


def sample_bias(gyro, bias_f, t_f, kf, seed, run_index, noise=True):
    """Gyro output: the mean rate over each sample's window [t - S/2, t + S/2] (clipped to the
    run), read from a quantised angle counter. Angle in arcsec = integral of deg/h over s."""
    nz = gyro["noise"]
    rng = _run_rng(seed, 3, run_index)   # gyro noise
    h = FINE_DT
    rate = bias_f.copy()
    nf = len(t_f)
    gm_w = rng.standard_normal(nf)
    turn_on = rng.standard_normal()
    arw_w = rng.standard_normal(2 * (nf - 1))
    phase = rng.random()
    if noise:
        # Gauss-Markov, exact discretisation on the 0.5 s grid: x' = -x/tau + white, var B^2
        B, tau = nz["bias_instability_dph"], nz["gauss_markov_time_s"]
        phi = math.exp(-h / tau)
        gm = np.empty(nf)
        gm[0] = B * gm_w[0]
        q = B * math.sqrt(1.0 - phi * phi)
        for k in range(1, nf):
            gm[k] = phi * gm[k - 1] + q * gm_w[k]
        rate = rate + gm + nz["turn_on_sigma_dph"] * turn_on
    # angle on the 0.25 s grid: trapezoid of the piecewise-linear rate, exact at midpoints too
    theta = np.empty(2 * nf - 1)
    inc = h * (rate[:-1] + rate[1:]) / 2.0
    theta[0::2] = np.concatenate([[0.0], np.cumsum(inc)])
    theta[1::2] = theta[0:-1:2] + h / 8.0 * (3.0 * rate[:-1] + rate[1:])
    if noise:
        # ARW: Wiener angle, increment sd 60 N sqrt(dt) arcsec over dt seconds
        # (sigma(tau) = N/sqrt(tau_h) deg/h = 60 N / sqrt(tau_s) deg/h)
        theta = theta + np.concatenate(
            [[0.0], np.cumsum(60.0 * nz["arw_deg_per_sqrt_h"] * math.sqrt(ANGLE_DT) * arw_w)])
        qa = nz["quantization_arcsec"]
        if qa > 0:
            theta = qa * np.floor(theta / qa + phase)
    # window edges on the 0.25 s grid (index 2 kf is time t_f[kf])
    S2 = (kf[1] - kf[0]) if len(kf) > 1 else 1   # half a sample period in 0.25 s units
    lo = np.maximum(2 * kf - S2, 0)
    hi = np.minimum(2 * kf + S2, 2 * kf[-1])
    if len(kf) == 1:
        lo, hi = np.array([0]), np.array([1])
    return (theta[hi] - theta[lo]) / ((hi - lo) * ANGLE_DT)


def csv_text(case, seed, period, strength, columns, runs_rows):
    L = ["# refgen reference data (tests/reference/refgen.py, written without rlgtherm's "
         "simulator): case %s, seed %d, sample period %s s, strength %s"
         % (case, seed, fmt_time(period), fmt_num(strength)),
         "# gyro: refgen-5node (truth in truth.json; nominal in nominal.toml)",
         ",".join(columns)]
    for run_id, rows in runs_rows:
        n = len(rows["t_s"])
        cols = []
        for c in columns[1:]:
            v = rows[c]
            if c == "t_s":
                cols.append([fmt_time(x) for x in v])
            elif c == "bias_dph":
                cols.append(["%.6f" % x for x in v])
            else:
                cols.append(["%.4f" % x for x in v])
        for i in range(n):
            L.append(run_id + "," + ",".join(col[i] for col in cols))
    return "\n".join(L) + "\n"


def generate(case, seed=1, period=1.0, strength=10.0, noise=True, exact_ambient=False):
    """Everything a case writes: {"data.csv": text, "nominal.toml": text, "truth.json": text}."""
    if case not in CASES:
        raise ValueError("unknown case '%s' (refgen.py --list)" % case)
    gyro = reference_gyro()
    effects, scaling = case_effects(case, strength)
    truth = simulate_truth(gyro, effects)
    nominal_effects = [e for e in effects if e["name"] == "sensor.lag" and case == "near.double_lag"
                       and e["parameters"]["time_constant_s"] == DOUBLE_LAG_KNOWN_S][:1]
    hidden = [e for e in effects if e not in nominal_effects]
    nom, factors = draw_nominal(gyro, _run_rng(seed, 1, 0), case)
    channels = sorted(gyro["sensors"])
    logged = ["P_%s_W" % s["name"] for s in gyro["sources"] if s["logged"]]
    columns = ["run", "t_s", "T_amb"] + channels + ["bias_dph"] + logged
    runs_rows = [(tr["run"]["id"], sample_run(gyro, tr, i, seed, period, noise, exact_ambient))
                 for i, tr in enumerate(truth)]
    data = csv_text(case, seed, period, strength, columns, runs_rows)
    header = ["refgen nominal gyro for case %s, seed %d: the reference gyro refgen-5node with"
              % (case, seed),
              "its thermal knobs drawn within [calibration] relative_uncertainty and its bias",
              "coefficients within 25 %; written without rlgtherm's simulator (truth.json)."]
    toml = nominal_toml(nom, nominal_effects, header)
    first = hidden[0] if hidden else None
    true_gyro = json.loads(json.dumps(gyro))
    truth_doc = {
        "generator": GENERATOR_VERSION,
        "case": case,
        "description": CASES[case],
        "near_form": case.startswith("near."),
        "expected_answer": EXPECTED.get(case, case if case != "none" else "none"),
        "effect": first["name"] if first else "none",
        "target": first["target"] if first else None,
        "parameters": first["parameters"] if first else {},
        "effects": hidden,
        "nominal_effects": nominal_effects,
        "strength": strength,
        "scaling": scaling,
        "sigma100": sigma100(gyro),
        "mode_spacing_C": mode_spacing_C(gyro),
        "seed": seed,
        "sample_period_s": period,
        "noise": noise,
        "exact_ambient": exact_ambient,
        "runs": RUNS,
        "columns": columns,
        "true_gyro": true_gyro,
        "nominal_factors": factors,
    }
    return {"data.csv": data, "nominal.toml": toml,
            "truth.json": json.dumps(truth_doc, indent=1, sort_keys=True) + "\n"}


def write_case(files, out_dir):
    os.makedirs(out_dir, exist_ok=True)
    for name, text in files.items():
        fd, tmp = tempfile.mkstemp(prefix="." + name + ".", dir=out_dir)
        with os.fdopen(fd, "w", newline="\n") as f:
            f.write(text)
        os.replace(tmp, os.path.join(out_dir, name))


def main(argv=None):
    ap = argparse.ArgumentParser(description="independent reference data for rlgtherm diagnose")
    ap.add_argument("case", nargs="?")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--sample-period", type=float, default=1.0)
    ap.add_argument("--strength", type=float, default=10.0,
                    help="effect size in 100 s noise RMS (see README)")
    ap.add_argument("--out", default=None)
    ap.add_argument("--noise-free", action="store_true")
    ap.add_argument("--exact-ambient", action="store_true",
                    help="write T_amb without the chamber sensor's noise (the rest unchanged)")
    ap.add_argument("--list", action="store_true")
    a = ap.parse_args(argv)
    if a.list:
        for k, v in CASES.items():
            print("%-24s %s" % (k, v))
        return 0
    if not a.case or not a.out:
        ap.error("CASE and --out DIR are required (or --list)")
    if a.seed < 0:
        ap.error("--seed must be >= 0")
    try:
        files = generate(a.case, a.seed, a.sample_period, a.strength, not a.noise_free,
                         a.exact_ambient)
    except ValueError as ex:
        print("refgen: " + str(ex), file=sys.stderr)
        return 2
    write_case(files, a.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
