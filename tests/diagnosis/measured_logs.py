#!/usr/bin/env python3
"""measured_logs.py: gyro logs at rest through chamber temperature profiles, made here with numpy
alone (none of rlgtherm's code: its polynomial, lag, play operator and catalog stay out), for
blind tests of `rlgtherm diagnose` without --gyro (tests/diagnosis/diagnose_blind_logs.py).

Each shape returns the log's text (as its logger writes it) and the truth the test may judge by,
never hand to the diagnosis: the bias's terms and the noise's sd of a 100 s mean.

  fog3   A FOG-like log: 12 h at 1 Hz, three 4 h chamber cycles -20 ... +60 °C at
         1 °C/min with dwells, the sensor a 600 s lag of the chamber plus 2 °C of self-heating;
         semicolon-separated, time in ms, decimal commas. Bias (°/h) = a quadratic in the sensor
         temperature + a rate term + a heating/cooling hysteresis of +-0.05 °/h (a Duhem loop:
         it relaxes towards +0.05 while heating and -0.05 while cooling over 2 °C of travel,
         not the model family's play operator) + white noise of 0.02 °/h per sample and a
         Gauss-Markov drift (600 s, 0.002 °/h).
  soak2  Another shape: 8 h at 2 s, two slow excursions -30 ... +70 °C through steps with soaks
         (no steady ramps), comma-separated, time in s, the rate in °/s. Bias = a cubic + a lag
         term k (T_L - T), T_L a 1500 s first-order lag of T (the bias follows an inner
         temperature the sensor does not read) + white noise of 0.05 °/h per sample.
  line1  A null shape for the all-clear: the fog3 profile, the bias a straight line in T and
         the white noise alone.
"""
import numpy as np


def _lag(x, dt, tau):
    """First-order lag of x (per sample, zero-order hold: the generator's own discretisation)."""
    a = np.exp(-dt / tau)
    out = np.empty_like(x)
    out[0] = x[0]
    for k in range(1, len(x)):
        out[k] = a * out[k - 1] + (1.0 - a) * x[k]
    return out


def _profile(segments, dt):
    """A chamber set point from (duration_s, target_C) segments, linear from the last target."""
    t, T = [0.0], [segments[0][1]]
    for duration, target in segments[1:]:
        n = int(round(duration / dt))
        t0, T0 = t[-1], T[-1]
        for k in range(1, n + 1):
            t.append(t0 + k * dt)
            T.append(T0 + (target - T0) * k / n)
    return np.array(t), np.array(T)


def _duhem(T, amplitude, travel_C):
    """A saturating heating/cooling loop: h moves towards +amplitude while T rises and towards
    -amplitude while it falls, by dh = (+-amplitude - h) |dT| / travel_C."""
    h = np.zeros_like(T)
    for k in range(1, len(T)):
        d = T[k] - T[k - 1]
        target = amplitude if d > 0 else -amplitude if d < 0 else h[k - 1]
        h[k] = h[k - 1] + (target - h[k - 1]) * min(1.0, abs(d) / travel_C)
    return h


def _fog_temperature(rng, dt=1.0):
    cycle = [(2400, 60.0), (1800, 60.0), (4800, -20.0), (1800, -20.0), (2400, 20.0), (1200, 20.0)]
    segments = [(0, 20.0)] + cycle * 3
    t, chamber = _profile(segments, dt)
    t, chamber = t[:43200], chamber[:43200]
    T = _lag(chamber, dt, 600.0) + 2.0
    return t, T + rng.normal(0.0, 0.003, T.size)  # sensor noise 3 mK


def _gm(rng, n, dt, tau, sd):
    a = np.exp(-dt / tau)
    w = rng.normal(0.0, sd * np.sqrt(1.0 - a * a), n)
    x = np.empty(n)
    x[0] = rng.normal(0.0, sd)
    for k in range(1, n):
        x[k] = a * x[k - 1] + w[k]
    return x


def _block_sd(noise, per_block):
    """The sd of the noise's 100 s means (non-overlapping), as drawn."""
    n = noise.size // per_block * per_block
    return float(np.sqrt(np.mean(noise[:n].reshape(-1, per_block).mean(axis=1) ** 2)))


def fog3(seed, quadratic=1.5e-4, rate=0.06, hysteresis=0.05):
    """The FOG-like log of item 1. rate: °/h per °C/min; quadratic: °/h per °C²."""
    rng = np.random.default_rng(seed)
    t, T = _fog_temperature(rng)
    Tc = _lag(T, 1.0, 1.0)  # the bias sees the sensor without its sensor noise: smooth it by 1 s
    d = Tc - 20.0
    rate_C_per_min = np.gradient(Tc, t) * 60.0
    noise = _gm(rng, t.size, 1.0, 600.0, 0.002) + rng.normal(0.0, 0.02, t.size)
    bias = 0.8 + 0.004 * d + quadratic * d * d + rate * rate_C_per_min + _duhem(Tc, hysteresis, 2.0) + noise
    lines = ["time_ms;temp_C;rate_dph"]
    for ti, Ti, bi in zip(t, T, bias):
        lines.append(f"{int(round(ti * 1000))};{Ti:.4f};{bi:.6f}".replace(".", ","))
    truth = {"noise_100s_dph": _block_sd(noise, 100),
             "terms": {"quadratic": quadratic, "rate": rate, "hysteresis": hysteresis}}
    return "\n".join(lines) + "\n", truth


def line1(seed):
    """The fog3 profile with a straight-line bias and white noise: nothing to find."""
    rng = np.random.default_rng(seed)
    t, T = _fog_temperature(rng)
    noise = rng.normal(0.0, 0.02, t.size)
    bias = 0.8 + 0.004 * (T - 20.0) + noise
    lines = ["time_ms;temp_C;rate_dph"]
    for ti, Ti, bi in zip(t, T, bias):
        lines.append(f"{int(round(ti * 1000))};{Ti:.4f};{bi:.6f}".replace(".", ","))
    return "\n".join(lines) + "\n", {"noise_100s_dph": _block_sd(noise, 100), "terms": {}}


def soak2(seed, lag=0.004, tau_s=1500.0):
    """Two excursions through steps and soaks at 2 s; lag: °/h per °C of T_L - T."""
    rng = np.random.default_rng(seed)
    dt = 2.0
    steps = [(0, 20.0), (600, 20.0)]
    for target in (-30.0, 0.0, 35.0, 70.0, 20.0) * 2:
        steps += [(300, target), (2400, target)]
    t, chamber = _profile(steps, dt)
    T = _lag(chamber, dt, 400.0) + rng.normal(0.0, 0.005, t.size)
    Ts = _lag(chamber, dt, 400.0)
    d = Ts - 20.0
    inner = _lag(Ts, dt, tau_s)
    noise = rng.normal(0.0, 0.05, t.size)
    bias = 2.0 + 0.01 * d - 2e-4 * d * d + 3e-6 * d ** 3 + lag * (inner - Ts) + noise
    lines = ["t,board_temp,gyro_z_dps"]
    for ti, Ti, bi in zip(t, T, bias):
        lines.append(f"{ti:.1f},{Ti:.4f},{bi / 3600.0:.10e}")
    return "\n".join(lines) + "\n", {"noise_100s_dph": _block_sd(noise, 50), "terms": {"lag": lag, "tau_s": tau_s}}


SHAPES = {"fog3": fog3, "soak2": soak2, "line1": line1}
