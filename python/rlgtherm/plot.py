"""Figures for a notebook: matplotlib Figures of what the CLI's `--plot DIR` draws
(tools/rlgtherm/verb_figures.h), from what the module's functions return, never recomputing a
reported number:

    compensation(run, compensated)   bias before and after compensation (`compensate --plot`'s
                                     bias_<run>.png): block means, the after alone, temperatures
    allan(result)                    an Allan deviation (`allan --plot`'s allan_<run>.png) with
                                     the noise terms its read-off resolved
    heldout(report)                  compare's held-out compensated bias against temperature, a
                                     panel per model (`compare --plot`'s heldout_<model>.png)
    pareto(answer)                   a plan's chamber hours against p95 |bias after|, the Pareto
                                     front, the target and the recommended candidate (pareto.png)

Each returns a matplotlib.figure.Figure made without pyplot (no global state, any thread): a
notebook shows it, `fig.savefig("x.png")` writes it. `import rlgtherm` does not import this
module or matplotlib; `import rlgtherm.plot` needs matplotlib (Debian's python3-matplotlib).
Units: time in h since power-on, temperatures in °C, bias in °/h.
"""
import math

import numpy as np

try:
    from matplotlib.figure import Figure
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter
except ImportError as e:  # an optional dependency: say which package brings it
    raise ImportError("rlgtherm.plot needs matplotlib (Debian's python3-matplotlib, or pip install matplotlib)") from e

import rlgtherm

__all__ = ["compensation", "allan", "heldout", "pareto"]

# The CLI's colours (tools/rlgtherm/plot_kit.h): before red, after blue, the sensors in turn.
RED, BLUE, GREEN, ORANGE, PURPLE, GREY = "#d62728", "#1f77b4", "#2ca02c", "#ff7f0e", "#9467bd", "#7f7f7f"
SENSOR_COLOURS = [RED, BLUE, GREEN, ORANGE, PURPLE]


def block_means(values, m):
    """Means of consecutive blocks of m samples, as the CLI's figures show a bias (1 s samples of
    a laser gyro are mostly white noise); a last, shorter block is dropped unless it is the only
    one (a mean of a few samples stands out as a spike)."""
    values = np.asarray(values, dtype=float)
    whole = len(values) // m
    if whole == 0:
        return np.array([values.mean()])
    return values[:whole * m].reshape(whole, m).mean(axis=1)


def block_size(t_s, block_s=100.0):
    """Samples per block of about block_s seconds (at least one), at the run's sample period."""
    dt = float(np.median(np.diff(t_s))) if len(t_s) > 1 else 1.0
    return max(1, int(round(block_s / dt))), dt


def readable_log_axis(axis):
    """Labels a log axis with plain numbers a reader can read values from ("0.02", "500"): 1, 2
    and 5 x 10^k where the axis spans up to three decades, else the decades (as the CLI's)."""
    lo, hi = axis.get_view_interval()
    fine = lo > 0 and math.log10(hi / lo) <= 3.0
    axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0) if fine else (1.0,)))
    axis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(NullFormatter())


def compensation(run, compensated, *, label="compensated", bias_column="bias_dph", block_s=100.0):
    """The bias of `run` before (its `bias_column`) and after compensation (`compensated`, °/h, one
    value per sample): three panels sharing the time axis, as `rlgtherm compensate --plot` draws
    bias_<run>.png: before and after as block means of about `block_s` s, the after alone on its
    own scale, and the run's temperature channels (names starting with T; the ambient dashed).
    `label` names the compensated series in the legends."""
    compensated = np.asarray(compensated, dtype=float)
    if compensated.shape != (len(run),):
        raise ValueError(f"run '{run.id}': compensated has shape {compensated.shape}, expected ({len(run)},): "
                         "one value per sample")
    m, dt = block_size(run.t_s, block_s)
    hours = block_means(run.t_s, m) / 3600.0
    before, after = block_means(run[bias_column], m), block_means(compensated, m)
    means = f"{m * dt:g} s means"
    fig = Figure(figsize=(10, 9), layout="constrained")
    top, middle, bottom = fig.subplots(3, 1, sharex=True)
    for ax in (top, middle):
        ax.axhline(0.0, color=GREY, linewidth=0.8)
        ax.set_ylabel("bias (°/h)")
    top.plot(hours, before, color=RED, label=f"before ({bias_column})")
    top.plot(hours, after, color=BLUE, label=f"after ({label})")
    top.set_title(f"run {run.id}: bias before and after compensation, {means}")
    top.legend(loc="best")
    middle.plot(hours, after, color=BLUE, label=f"after ({label})")
    middle.set_title(f"run {run.id}: after compensation alone, {means}")
    middle.legend(loc="best")
    sensors = 0
    for name in run.names:
        if len(name) < 2 or name[0] != "T":
            continue
        if name == "T_amb":
            bottom.plot(hours, block_means(run[name], m), color="black", linestyle="--", label=f"{name} (dashed)")
        else:
            bottom.plot(hours, block_means(run[name], m), color=SENSOR_COLOURS[sensors % 5],
                        linestyle="-" if sensors < 5 else "--", label=name)
            sensors += 1
    bottom.set_title(f"run {run.id}: temperatures, {means}")
    bottom.set_ylabel("temperature (°C)")
    bottom.set_xlabel("time since power-on (h)")
    if bottom.lines:
        bottom.legend(loc="best")
    return fig


# The read-off's terms (model/allan.h): the report's key, its name, unit, the line sigma(tau) in
# °/h from the reported value, where it is read (tau in s; None: the flat floor) and the colour.
# ARW is reported in °/sqrt(h) = N / 60 with N in °/h sqrt(s); RRW in °/h/sqrt(h) = 60 K with K in
# °/h / sqrt(s) (model/allan.cpp, ReportScale).
ALLAN_TERMS = [
    ("arw_deg_per_sqrt_h", "ARW", "°/√h", "σ at τ = 1 s, slope -1/2", lambda v, tau: 60.0 * v / np.sqrt(tau), 1.0, RED),
    ("bias_instability_dph", "bias instability", "°/h", "floor σ = 0.664 B",
     lambda v, tau: np.full_like(tau, 0.664 * v), None, GREEN),
    ("rrw_deg_per_h_per_sqrt_h", "RRW", "°/h/√h", "σ at τ = 3 s, slope +1/2",
     lambda v, tau: v / 60.0 * np.sqrt(tau / 3.0), 3.0, PURPLE),
]


def allan(result, *, column="bias_dph", title=None):
    """An Allan deviation as `rlgtherm allan --plot` draws allan_<run>.png: the measured curve
    (log-log) and, dashed, the line of each noise term the read-off resolved, marked where it is
    read; the terms it does not resolve are named with their upper bound under the axes.
    result: the dict of rlgtherm.allan (or of its Allan terms: tau_s, adev_dph and the read-offs),
    or a Run, whose `column` is analysed with rlgtherm.allan first."""
    if isinstance(result, rlgtherm.Run):
        run = result
        result = rlgtherm.allan(run, column)
        title = title or f"run {run.id}: Allan deviation of {column}"
    for key in ("tau_s", "adev_dph"):
        if key not in result:
            raise ValueError(f"allan: expected the dict of rlgtherm.allan, which has '{key}'")
    tau, adev = np.asarray(result["tau_s"], dtype=float), np.asarray(result["adev_dph"], dtype=float)
    positive = adev > 0.0  # a log axis has no place for 0
    tau, adev = tau[positive], adev[positive]
    fig = Figure(figsize=(9, 7), layout="constrained")
    ax = fig.subplots()
    ax.loglog(tau, adev, color="black", marker="o", markersize=3, label="measured σ(τ), overlapping, octave τ")
    span = np.geomspace(min(tau.min(), 1.0) / 1.5, tau.max() * 1.5, 60) if len(tau) else np.geomspace(0.5, 10, 60)
    notes = []
    for key, name, unit, where, sigma, read_at, colour in ALLAN_TERMS:
        value = result.get(key)
        if value is None:
            bound = (result.get("not_resolved") or {}).get(key, {}).get("upper_bound")
            notes.append(f"{name}: not resolved" + (f" (< {bound:.5f} {unit})" if bound is not None else "")
                         + ", no line drawn")
            continue
        ax.loglog(span, sigma(value, span), color=colour, linestyle="--", label=f"{name} {value:.5f} {unit} ({where})")
        if read_at is not None:
            ax.loglog([read_at], sigma(value, np.array([read_at])), color=colour, marker="o", markersize=7,
                      linestyle="none")
    ax.set_xlabel("averaging time τ (s)")
    ax.set_ylabel("Allan deviation σ(τ) (°/h)")
    readable_log_axis(ax.xaxis)
    readable_log_axis(ax.yaxis)
    ax.set_title(title or f"run {result.get('run', '')}: Allan deviation".replace("run : ", ""))
    ax.grid(True, which="both", color="#dddddd", linewidth=0.5)
    ax.legend(loc="best", fontsize="small", title="dashed: fitted noise terms (IEEE Std 952)", title_fontsize="small")
    if notes:
        fig.text(0.01, 0.005, "\n".join(notes), color=GREY, fontsize="small", va="bottom")
        fig.get_layout_engine().set(rect=(0, 0.03 * len(notes), 1, 1 - 0.03 * len(notes)))
    return fig


def heldout(report, models=None, *, bins=40):
    """compare's held-out compensated bias against temperature, as `rlgtherm compare --plot` draws
    heldout_<model>.png: a panel per model (a shared bias axis, so that they compare), every
    held-out sample a grey dot and the means over 1/bins of the temperature range in blue.
    report: the dict of rlgtherm.compare; models: labels (or entries of report["models"]) to draw,
    default every fitted model in the report's order (its ranking)."""
    fitted = [m for m in report.get("models", []) if "heldout_T" in m]
    if models is None:
        chosen = fitted
    else:
        by_label = {m["label"]: m for m in fitted}
        chosen = []
        for m in models:
            label = m["label"] if isinstance(m, dict) else m
            if label not in by_label:
                raise ValueError(f"heldout: no fitted model '{label}' in the report (models: {', '.join(by_label)})")
            chosen.append(by_label[label])
    if not chosen:
        raise ValueError("heldout: no fitted model with held-out samples: expected the dict of rlgtherm.compare")
    cols = min(2, len(chosen))
    rows = math.ceil(len(chosen) / cols)
    fig = Figure(figsize=(6.5 * cols, 4.2 * rows), layout="constrained")
    axes = fig.subplots(rows, cols, sharey=True, squeeze=False).ravel()
    for ax, m in zip(axes, chosen):
        T, residual = np.asarray(m["heldout_T"]), np.asarray(m["heldout_compensated_dph"])
        ax.axhline(0.0, color="black", linestyle="--", linewidth=0.8)
        ax.plot(T, residual, linestyle="none", marker=".", markersize=2 if len(T) >= 300 else 4, color=GREY,
                alpha=0.5, label="held-out samples")
        lo, hi = float(T.min()), float(T.max())
        width = (hi - lo) / bins if hi > lo else 1.0
        index = np.clip(((T - lo) / width).astype(int), 0, bins - 1)
        counts = np.bincount(index, minlength=bins)
        sums = np.bincount(index, weights=residual, minlength=bins)
        filled = counts > 0
        centres = lo + (np.arange(bins) + 0.5) * width
        ax.plot(centres[filled], sums[filled] / counts[filled], color=BLUE, marker="o", markersize=3,
                label=f"means over 1/{bins} of the range")
        ax.set_title(f"{m['label']}: {m['heldout_rms_dph']:.4f} °/h RMS held out", fontsize="medium")
        ax.set_xlabel(f"{m['heldout_channel']} (°C)")
        ax.set_ylabel("compensated bias (°/h)")
        ax.legend(loc="best", fontsize="small")
    for ax in axes[len(chosen):]:
        ax.set_visible(False)
    fig.suptitle(f"{report.get('data', 'compare')}: held-out compensated bias (trained on other data)")
    return fig


def pareto(answer):
    """A calibration plan's answer as `rlgtherm plan --plot` draws pareto.png: each candidate's
    chamber hours against its predicted p95 |bias after| over the gyros (log axis) with its 90 %
    interval (an open end drawn to the edge), the Pareto front as a staircase (the best p95 so
    many hours buy), the target dashed red, the recommended candidate ringed. answer: the dict of
    rlgtherm.plan (or plan_merge)."""
    points = [c for c in answer.get("candidates", []) if c.get("p95_abs_bias_after_dph") is not None]
    if not points:
        raise ValueError("pareto: no candidate with numbers: expected the dict of rlgtherm.plan")
    target = answer["target"]["p95_abs_bias_after_dph"]
    hours = np.array([c["chamber_h"] for c in points], dtype=float)
    p95 = np.array([c["p95_abs_bias_after_dph"] for c in points], dtype=float)
    values = [target, *p95]
    for c in points:
        values += [v for v in c["p95_interval_dph"] if v is not None and v > 0]
    y_lo, y_hi = min(values) / 10 ** 0.15, max(values) * 10 ** 0.15
    x_hi = hours.max() * 1.08 + 1.0
    fig = Figure(figsize=(11, 7.5), layout="constrained")
    ax = fig.subplots()
    ax.set_yscale("log")
    ax.set_xlim(0.0, x_hi)
    ax.set_ylim(y_lo, y_hi)
    ax.axhline(target, color=RED, linestyle="--", label=f"target {target:g} °/h")
    front = sorted((c for c in points if c["pareto"]), key=lambda c: c["chamber_h"])
    if front:
        fx = [c["chamber_h"] for c in front] + [x_hi]
        fy = [c["p95_abs_bias_after_dph"] for c in front]
        ax.step(fx, fy + fy[-1:], where="post", color=GREEN, label="Pareto front")
    lower = [p - (c["p95_interval_dph"][0] if c["p95_interval_dph"][0] else y_lo) for c, p in zip(points, p95)]
    upper = [(c["p95_interval_dph"][1] if c["p95_interval_dph"][1] is not None else y_hi) - p for c, p in zip(points, p95)]
    ax.errorbar(hours, p95, yerr=[lower, upper], fmt="o", color=BLUE, capsize=4, label="candidate, 90 % interval")
    recommended = [c for c in points if c["name"] == answer.get("recommended")]
    ax.plot([c["chamber_h"] for c in recommended], [c["p95_abs_bias_after_dph"] for c in recommended], marker="o",
            markersize=16, markerfacecolor="none", markeredgecolor=ORANGE, linestyle="none",
            label="recommended" if recommended else "recommended: none")
    # Numbered in the plan's order (the # of `plan`'s table) and named in a key under the axes, as
    # the CLI's: names beside points of equal hours (three soaks of 1 h, five of 2 h) would
    # overwrite each other. Numbers alternately right and left keep neighbours apart.
    key = [""]
    for k, c in enumerate(points):
        ax.annotate(str(k + 1), (c["chamber_h"], c["p95_abs_bias_after_dph"]), xytext=(6 if k % 2 == 0 else -6, -3),
                    textcoords="offset points", ha="left" if k % 2 == 0 else "right", fontsize="small")
        entry = f"{k + 1} {c['name']}"
        if key[-1] and len(key[-1]) + len(entry) + 3 > 110:
            key.append("")
        key[-1] += ("   " if key[-1] else "") + entry
    fig.text(0.01, 0.005, "\n".join(key), fontsize="small", va="bottom")
    fig.get_layout_engine().set(rect=(0, 0.03 * len(key), 1, 1 - 0.03 * len(key)))
    readable_log_axis(ax.yaxis)
    ax.set_xlabel("chamber hours (settling + runs)")
    ax.set_ylabel("p95 |bias after| over gyros (°/h)")
    ax.set_title(f"{answer.get('plan', 'plan')}: {answer.get('gyros')} gyros, worst service run per gyro")
    ax.grid(True, which="both", color="#dddddd", linewidth=0.5)
    ax.legend(loc="best", fontsize="small")
    return fig
