"""Self-tests of the reference generator (run: /usr/bin/python3 -m pytest tests/reference).

Closed forms and round trips; every tolerance says why it is what it is."""

import csv
import io
import json
import math
import os
import sys

import numpy as np
import pytest
from scipy.optimize import fsolve

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import refgen  # noqa: E402


def one_node_gyro(C=380.0, G=0.3, P=1.0, lags=()):
    g = refgen.reference_gyro()
    g["nodes"] = [{"name": "block", "C": C}]
    g["links"] = [["block", "ambient", G]]
    g["sources"] = [{"name": "heater", "power_W": P, "gain": 1.0, "logged": True,
                     "shares": {"block": 1.0}}]
    g["sensors"] = {"T1": {"node": "block", "noise_C": 0.0, "resolution_C": 0.0,
                           "lags_s": list(lags)}}
    g["bias"]["langmuir_gradient"] = []
    return g


def constant_run(T_amb, duration, power=None):
    r = {"id": "c", "duration_s": duration, "ambient": [[0, T_amb], [duration, T_amb]]}
    if power is not None:
        r["power"] = power
    return r


def steady_state(gyro):
    """Closed form of the linear network at rest: (K + diag(Ga)) T = Ga T_amb + P."""
    net = refgen.Network(gyro)
    P = np.zeros(net.n_nodes)
    for s, share, gain, _ in net.sources:
        P += share * gain * s["power_W"]
    return net, np.linalg.solve(net.K + np.diag(net.Ga), net.Ga * 20.0 + P)


def slowest_time_constant(net):
    A, _ = net.matrices([s["power_W"] for s, _, _, _ in net.sources])
    return 1.0 / min(abs(np.linalg.eigvals(A).real))


def test_steady_state_equals_closed_form_expm():
    gyro = refgen.reference_gyro()
    net, T_ss = steady_state(gyro)
    tau = slowest_time_constant(net)
    # 40 slowest time constants: the start-up transient has decayed by e^-40 ~ 4e-18 of its
    # ~5 degC size; what is left is roundoff of ~100 exact propagation steps (~1e-13 degC).
    dur = 60.0 * math.ceil(40 * tau / 60.0)
    sim = refgen.simulate_run(net, constant_run(20.0, dur), dt=60.0, method="expm")
    np.testing.assert_allclose(sim["x"][-1, :net.n_nodes], T_ss, rtol=0, atol=1e-9)
    # and the state does not move there: the right derivative is zero to roundoff
    assert np.max(np.abs(sim["xdot"][-1])) < 1e-12


def test_steady_state_equals_closed_form_radau():
    gyro = refgen.reference_gyro()
    net, T_ss = steady_state(gyro)
    tau = slowest_time_constant(net)
    dur = 60.0 * math.ceil(30 * tau / 60.0)
    sim = refgen.simulate_run(net, constant_run(20.0, dur), dt=60.0, method="ivp")
    # Radau at rtol = atol = 1e-10 on temperatures of ~25 degC: a few 1e-9 degC of global error;
    # e^-30 of the transient is 1e-13 degC.
    np.testing.assert_allclose(sim["x"][-1, :net.n_nodes], T_ss, rtol=0, atol=1e-7)


def test_steady_state_with_radiation_solves_the_nonlinear_balance():
    gyro = refgen.reference_gyro()
    g = refgen.apply_thermal_effects(gyro, [refgen._e("thermal.radiation", "block-housing",
                                                      emissivity_area_m2=0.02)])
    net = refgen.Network(g)
    tau = slowest_time_constant(net)
    dur = 60.0 * math.ceil(30 * tau / 60.0)
    sim = refgen.simulate_run(net, constant_run(20.0, dur), dt=60.0)
    A, B = net.matrices([s["power_W"] for s, _, _, _ in net.sources])

    def f(x):
        return A @ x + B[:, 0] * 20.0 + B[:, 1] + net.radiation(x, 20.0)

    x_ss = fsolve(f, sim["x"][-1], xtol=1e-14)
    # same Radau error budget as above
    np.testing.assert_allclose(sim["x"][-1], x_ss, rtol=0, atol=1e-7)


@pytest.mark.parametrize("method,atol", [("expm", 1e-10), ("ivp", 1e-7)])
def test_single_node_step_response_is_the_exponential(method, atol):
    # expm: exact propagation, roundoff only (~1e-14 degC per step over 7200 steps);
    # ivp: Radau rtol = atol = 1e-10 on ~23 degC.
    C, G, P = 380.0, 0.3, 1.0
    gyro = one_node_gyro(C, G, P)
    net = refgen.Network(gyro)
    run = constant_run(20.0, 3600.0, power={"heater": [[0, P]]})
    sim = refgen.simulate_run(net, run, dt=0.5, method=method)
    t = sim["t"]
    closed = 20.0 + P / G * (1.0 - np.exp(-t * G / C))
    np.testing.assert_allclose(sim["x"][:, 0], closed, rtol=0, atol=atol)
    # its derivative too (used by bias.temperature_rate)
    np.testing.assert_allclose(sim["xdot"][:, 0], P / C * np.exp(-t * G / C), rtol=0,
                               atol=atol / 100)


def test_two_lags_give_the_cascaded_step_response():
    # The reading of a node behind two first-order lags (near.double_lag). A node step is made
    # by a very light node (C/G = 1 ms), so the reading's closed form is that of two lags of a
    # step, exact to e^(-t/1 ms) plus a 1 ms shift: 1e-3 / 30 s of the 10 degC step at most.
    C, G = 3e-4, 0.3
    tau1, tau2 = 30.0, 7.0
    gyro = one_node_gyro(C, G, 3.0, lags=(tau1, tau2))
    net = refgen.Network(gyro)
    run = constant_run(20.0, 600.0, power={"heater": [[0, 3.0]]})
    sim = refgen.simulate_run(net, run, dt=0.5, method="expm")
    t = sim["t"]
    step = 3.0 / G
    closed = 20.0 + step * (1 - (tau1 * np.exp(-t / tau1) - tau2 * np.exp(-t / tau2)) / (tau1 - tau2))
    reading = sim["x"][:, net.channel_state["T1"]]
    np.testing.assert_allclose(reading, closed, rtol=0, atol=step * 1e-3 / tau2)


def test_matrix_exponential_and_radau_agree_on_a_linear_network_with_every_linear_effect():
    g = refgen.apply_thermal_effects(refgen.reference_gyro(), [
        refgen._e("thermal.missing_mass", "block-housing", heat_capacity_J_per_K=150.0,
                  conductance_W_per_K=0.2),
        refgen._e("thermal.power_drift", "cathode", g_per_C=0.005, reference_C=20.0),
        refgen._e("sensor.lag", "T2", time_constant_s=20.0)])
    net = refgen.Network(g)
    run = refgen.RUNS[2]   # warm-up at 5 degC and a power step
    a = refgen.simulate_run(net, run, dt=10.0, method="expm")
    b = refgen.simulate_run(net, run, dt=10.0, method="ivp")
    # two independent methods; Radau's global error at rtol = atol = 1e-10 is ~1e-8 degC
    np.testing.assert_allclose(a["x"], b["x"], rtol=0, atol=1e-6)


def test_energy_balance_with_mass_drift_and_radiation():
    g = refgen.apply_thermal_effects(refgen.reference_gyro(), [
        refgen._e("thermal.missing_mass", "block-housing", heat_capacity_J_per_K=150.0,
                  conductance_W_per_K=0.2),
        refgen._e("thermal.power_drift", "cathode", g_per_C=0.005, reference_C=20.0),
        refgen._e("thermal.radiation", "block-ambient", emissivity_area_m2=0.01)])
    net = refgen.Network(g)
    run = refgen.RUNS[0]   # the ramp: large heat flows in and out
    sim = refgen.simulate_run(net, run, dt=0.5)
    x, amb, P, t = sim["x"], sim["T_amb"], sim["P"], sim["t"]
    nn = net.n_nodes
    stored = float(np.sum(net.C * (x[-1, :nn] - x[0, :nn])))
    heat = np.zeros(len(t))
    for (s, share, gain, drift), j in zip(net.sources, range(P.shape[1])):
        f = np.ones(len(t)) if drift is None else 1 + drift[1] * (x[:, drift[0]] - drift[2])
        heat += share.sum() * gain * P[:, j] * f
    heat += (amb[:, None] - x[:, :nn]) @ net.Ga
    for ia, ib, eA in net.rad:
        assert ib is None
        heat += eA * refgen.SIGMA_SB * ((amb + 273.15) ** 4 - (x[:, ia] + 273.15) ** 4)
    inflow = float(np.sum((heat[1:] + heat[:-1]) / 2) * 0.5)
    throughput = float(np.sum(np.abs(heat)) * 0.5)
    # trapezoid on a 0.5 s grid over flows whose fastest time constant is ~3 min: relative error
    # ~(h/tau)^2/12 ~ 1e-7 of the heat throughput (Radau's own error is 1e-10 relative)
    assert abs(stored - inflow) < 1e-6 * throughput, (stored, inflow, throughput)


def test_hysteresis_accumulates_separate_heating_and_cooling_slopes():
    g = refgen.reference_gyro()
    net = refgen.Network(g)
    run = {"id": "up-down", "duration_s": 7200.0,
           "ambient": [[0, 20], [1800, 30], [5400, 10], [7200, 10]]}
    sim = refgen.simulate_run(net, run, dt=5.0)
    e = refgen._e("bias.hysteresis", "block", k_heating_dph_per_C=0.3, k_cooling_dph_per_C=0.1)
    term = refgen.bias_effect_term(g, net, sim, e)
    T = sim["x"][:, net.idx["block"]]
    d = np.diff(T)
    up, down = d[d > 0].sum(), d[d < 0].sum()
    # a sum of the same increments in another order: roundoff only
    assert abs(term[-1] - (0.3 * up + 0.1 * down)) < 1e-12


def test_mode_hops_reset_past_the_range_and_reversible_hops_do_not_remember():
    g = refgen.reference_gyro()
    net = refgen.Network(g)
    s = refgen.mode_spacing_C(g)
    # block up by ~1.5 spacings and back down to where it started
    run = {"id": "there-and-back", "duration_s": 30000.0,
           "ambient": [[0, 0], [600, 0], [4600, 34], [8000, 34], [12000, 0], [30000, 0]]}
    sim = refgen.simulate_run(net, run, dt=5.0)
    T = sim["x"][:, net.idx["block"]]
    hop = refgen.bias_effect_term(g, net, sim, refgen._e("bias.mode_hop", "block", step_dph=1.0,
                                                         range_modes=0.6, mode_spacing_C=s))
    travel = (T - T[0]) / s - hop   # PLC travel in modes: always within the range
    assert np.max(np.abs(travel)) <= 0.6 + 1e-12
    assert hop.max() == 1.0
    # hysteresis: at the same block temperature on the way down the count is still 1 until
    # the travel falls below -0.6, i.e. at (T - T0)/s < 0.4, not at 0.6 where it rose
    k_up = np.argmax(hop > 0.5)
    k_down = k_up + np.argmax(hop[k_up:] < 0.5)
    # (a 5 s grid step moves the block by < 0.01 degC, 5e-4 modes: abs 1e-3)
    assert (T[k_up] - T[0]) / s == pytest.approx(0.6, abs=1e-3)
    assert (T[k_down] - T[0]) / s == pytest.approx(0.4, abs=1e-3)
    rev = refgen.bias_effect_term(g, net, sim, refgen._e(
        "near.reversible_hops", "block", step_dph=1.0, spacing_C=13.0, first_edge_C=3.5))
    # no memory: the bias is a function of the block temperature alone
    np.testing.assert_array_equal(rev, np.floor((T - 3.5) / 13.0))


# ---- generated files ----------------------------------------------------------------------

@pytest.fixture(scope="module")
def none_files():
    return {p: refgen.generate("none", seed=5, period=p) for p in (1.0, 10.0, 60.0)}


def read_csv(text):
    lines = [ln for ln in text.splitlines() if not ln.startswith("#")]
    rows = list(csv.reader(io.StringIO("\n".join(lines))))
    return rows[0], rows[1:]


def test_csv_parses_back_with_the_declared_columns(none_files):
    files = none_files[10.0]
    truth = json.loads(files["truth.json"])
    header, rows = read_csv(files["data.csv"])
    assert header == truth["columns"]
    assert header[:3] == ["run", "t_s", "T_amb"] and "T1" in header and "bias_dph" in header
    runs = {}
    for r in rows:
        assert len(r) == len(header)
        runs.setdefault(r[0], []).append(r)
    assert list(runs) == [run["id"] for run in refgen.RUNS]   # grouped, in order
    for run in refgen.RUNS:
        rr = runs[run["id"]]
        t = np.array([float(r[1]) for r in rr])
        assert t[0] == 0 and np.all(np.diff(t) == 10.0) and t[-1] == run["duration_s"]
        for j, col in enumerate(header[2:], start=2):
            v = np.array([float(r[j]) for r in rr])
            assert np.all(np.isfinite(v))
            decimals = 6 if col == "bias_dph" else 4   # docs/data-format.md
            assert all(len(r[j].split(".")[1]) == decimals for r in rr)
            if col.startswith("T"):
                assert np.all((v > -80) & (v < 150))
    # the logged power is the run's commanded power
    pw = [float(r[header.index("P_discharge_W")]) for r in runs["dwell5-power"]]
    assert pw[0] == 0.8 and pw[-1] == 1.05


def test_nominal_toml_is_valid_toml_with_the_gyro_keys(none_files):
    tomllib = pytest.importorskip("tomllib")   # Python 3.11
    nom = tomllib.loads(none_files[10.0]["nominal.toml"])
    assert [n["name"] for n in nom["nodes"]] == ["block", "anode", "cathode", "mount", "housing"]
    assert set(nom["sensors"]) == {"T1", "T2", "T3"}
    assert nom["bias"]["node"] == "block" and nom["calibration"]["relative_uncertainty"] == 0.06
    # drawn within 2 prior sigma (z clipped to +-2)
    truth = json.loads(none_files[10.0]["truth.json"])
    for k, f in truth["nominal_factors"].items():
        if k.split(":")[0] in ("C", "G", "P", "gain"):
            assert abs(math.log(f)) <= 2 * 0.06 + 1e-12, k


def test_same_seed_gives_byte_identical_files():
    a = refgen.generate("bias.gradient", seed=9, period=60.0, strength=4.0)
    b = refgen.generate("bias.gradient", seed=9, period=60.0, strength=4.0)
    assert a == b
    c = refgen.generate("bias.gradient", seed=10, period=60.0, strength=4.0)
    assert c["data.csv"] != a["data.csv"] and c["nominal.toml"] != a["nominal.toml"]


def test_effect_is_sized_to_the_requested_strength():
    truth = json.loads(refgen.generate("thermal.missing_link", seed=1, period=60.0,
                                       strength=4.0)["truth.json"])
    # Brent's root in log s to 1e-4: the strength to ~1e-4 relative
    assert truth["scaling"]["achieved_strength"] == pytest.approx(4.0, rel=1e-3)
    assert truth["scaling"]["achieved_strength"] <= max(
        truth["scaling"]["strength_raw_per_channel"].values())


def test_sample_periods_read_the_same_experiment(none_files):
    parsed = {}
    for p, files in none_files.items():
        header, rows = read_csv(files["data.csv"])
        parsed[p] = (header, rows)
    t1 = {}
    for p, (header, rows) in parsed.items():
        j = header.index("T1")
        t1[p] = {(r[0], float(r[1])): r[j] for r in rows}
    # temperatures at common times are the same readings (one noise realisation per experiment)
    for key, v in t1[60.0].items():
        assert t1[1.0][key] == v and t1[10.0][key] == v
    # the gyro's total angle over a run is the same whatever the period (the windows tile the
    # run): sum(rate * window) agrees to the 6-decimal rounding of the CSV
    for run in refgen.RUNS:
        totals = []
        for p, (header, rows) in parsed.items():
            b = np.array([float(r[header.index("bias_dph")]) for r in rows if r[0] == run["id"]])
            w = np.full(len(b), p)
            w[0] = w[-1] = p / 2
            totals.append((b * w).sum())
            nrows = len(b)
        # rounding to 1e-6 deg/h: at most 0.5e-6 * (window) per sample, i.e. 0.5e-6 * duration
        assert max(totals) - min(totals) <= 0.5e-6 * run["duration_s"] * 2, totals
        assert nrows == run["duration_s"] / 60 + 1
    # 600 s block means from the angle counter: each period's cumulative angle at its window
    # edges, interpolated linearly to multiples of 600 s. Interpolating inside a window of S
    # seconds errs by the ARW's Brownian bridge (sd at mid-window 60 N sqrt(S/4) arcsec) and by
    # the bias's slope over the window (at most max|dB/dt| S^2/8 arcsec); two periods, two ends:
    # 6 sd of the bridge plus twice the slope bound, over 600 s. Independent experiments would
    # differ by the 600 s noise itself (~0.005 deg/h per block) and fail this.
    truth = refgen.simulate_truth(refgen.reference_gyro(), [])
    N = refgen.reference_gyro()["noise"]["arw_deg_per_sqrt_h"]
    for i, run in enumerate(refgen.RUNS):
        slope = np.max(np.abs(np.diff(truth[i]["bias"]))) / refgen.FINE_DT
        edges600 = np.arange(0.0, run["duration_s"] + 1, 600.0)
        means = {}
        for p, (header, rows) in parsed.items():
            b = np.array([float(r[header.index("bias_dph")]) for r in rows if r[0] == run["id"]])
            t = np.arange(len(b)) * p
            edges = np.concatenate([[0.0], t[:-1] + p / 2, [t[-1]]])
            theta = np.concatenate([[0.0], np.cumsum(b * np.diff(edges))])
            means[p] = np.diff(np.interp(edges600, edges, theta)) / 600.0
        for p in (10.0, 60.0):
            tol = (6 * 2 * 60 * N * math.sqrt(p / 4) + 2 * slope * p * p / 8) / 600.0
            assert np.max(np.abs(means[p] - means[1.0])) < tol, (p, tol)


def test_exact_ambient_changes_only_the_ambient_column():
    a = refgen.generate("none", seed=4, period=60.0)
    b = refgen.generate("none", seed=4, period=60.0, exact_ambient=True)
    ha, ra = read_csv(a["data.csv"])
    hb, rb = read_csv(b["data.csv"])
    j = ha.index("T_amb")
    assert ha == hb and any(x[j] != y[j] for x, y in zip(ra, rb))
    assert [x[:j] + x[j + 1:] for x in ra] == [y[:j] + y[j + 1:] for y in rb]
    truth = json.loads(b["truth.json"])
    # the exact column is the chamber profile itself (to the CSV's 0.1 mK)
    for r in rb:
        run = next(u for u in refgen.RUNS if u["id"] == r[0])
        assert abs(float(r[j]) - refgen.run_ambient(run, float(r[1]))) <= 0.5e-4 + 1e-12
    assert truth["exact_ambient"] is True


def test_truth_and_nominal_do_not_depend_on_the_sample_period(none_files):
    a = json.loads(none_files[1.0]["truth.json"])
    b = json.loads(none_files[60.0]["truth.json"])
    a.pop("sample_period_s"), b.pop("sample_period_s")
    assert a == b
    assert none_files[1.0]["nominal.toml"] == none_files[60.0]["nominal.toml"]


def test_noise_has_the_stated_levels(none_files):
    header, rows = read_csv(none_files[1.0]["data.csv"])
    g = refgen.reference_gyro()
    for col, want in (("bias_dph", 60 * g["noise"]["arw_deg_per_sqrt_h"]),
                      ("T1", math.sqrt(0.002 ** 2 + 0.001 ** 2 / 12))):
        j = header.index(col)
        d = []
        for run in refgen.RUNS:
            v = np.array([float(r[j]) for r in rows if r[0] == run["id"]])
            d.append(np.diff(v, 2))
        d = np.concatenate(d)
        # second differences remove the slow parts (the thermal trend and its slope; the
        # Gauss-Markov's 1 s increments have sd B sqrt(2/3600) = 1e-4 deg/h); white noise has
        # var(second difference) = 6 var. 36,000 differences: the estimate's sampling error is
        # ~1 %; 3 % leaves room for quantization and the 0.25 s first windows.
        got = np.std(d) / math.sqrt(6)
        assert got == pytest.approx(want, rel=0.03), col


def test_cli_lists_the_cases_and_writes_the_three_files(tmp_path, capsys):
    assert refgen.main(["--list"]) == 0
    out = capsys.readouterr().out
    for case in ("none", "bias.mode_hop", "near.reversible_hops", "near.heavy_nominal"):
        assert case in out
    assert refgen.main(["none", "--seed", "2", "--sample-period", "60", "--out",
                        str(tmp_path / "x")]) == 0
    assert sorted(os.listdir(tmp_path / "x")) == ["data.csv", "nominal.toml", "truth.json"]
    assert refgen.main(["nope", "--out", str(tmp_path / "y")]) == 2
    assert refgen.main(["none", "--sample-period", "0.3", "--out", str(tmp_path / "z")]) == 2
