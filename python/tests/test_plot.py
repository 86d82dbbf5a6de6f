"""The notebook figures (rlgtherm.plot, docs/python.md "In a notebook"): each function returns a
matplotlib Figure whose axes and lines hold what the module's functions returned, as the CLI's
--plot figures do, and renders to PNG. matplotlib is optional: `import rlgtherm.plot` without it
is an ImportError that names the package."""
import subprocess
import sys
import warnings

import numpy as np
import pytest

import rlgtherm
from conftest import SOURCE

pytest.importorskip("matplotlib")
import rlgtherm.plot as rp  # noqa: E402 (after the skip)
from matplotlib.figure import Figure  # noqa: E402

PAPER = str(SOURCE / "scenarios/paper-fixed.toml")


@pytest.fixture(scope="module")
def warmup():
    """The paper's +60 °C warm-up (7201 samples at 1 s) and its Eq. (2) compensation fitted on the
    other nine."""
    data = rlgtherm.simulate(PAPER, seed=1)
    coeffs = rlgtherm.fit(data, pair=("T1", "T2"), runs=data.ids[:9])
    run = data["fixed+60"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # +60 °C is beyond the fitted range
        return run, rlgtherm.Compensator(coeffs).compensate_run(run)


def lines(ax, label):
    found = [line for line in ax.get_lines() if line.get_label() == label]
    assert len(found) == 1, [line.get_label() for line in ax.get_lines()]
    return found[0]


def renders(fig, tmp_path):
    fig.savefig(tmp_path / "f.png", dpi=50)
    assert (tmp_path / "f.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_compensation_shows_the_block_means_before_and_after_and_the_temperatures(warmup, tmp_path):
    run, comp = warmup
    fig = rp.compensation(run, comp, label="Eq. (2)")
    assert isinstance(fig, Figure)
    top, middle, bottom = fig.axes
    # 100 s means of 1 s samples: 72 whole blocks of 7201 samples, the last sample dropped.
    means = lambda v: np.asarray(v)[:7200].reshape(72, 100).mean(axis=1)  # noqa: E731
    np.testing.assert_array_equal(lines(top, "before (bias_dph)").get_ydata(), means(run["bias_dph"]))
    np.testing.assert_array_equal(lines(top, "after (Eq. (2))").get_ydata(), means(comp))
    np.testing.assert_array_equal(lines(middle, "after (Eq. (2))").get_xdata(), means(run.t_s) / 3600)
    assert [line.get_label() for line in bottom.get_lines()] == ["T_amb (dashed)", "T1", "T2", "T3", "T4"]
    assert lines(bottom, "T_amb (dashed)").get_linestyle() == "--"
    assert top.get_title() == "run fixed+60: bias before and after compensation, 100 s means"
    assert bottom.get_xlabel() == "time since power-on (h)"
    renders(fig, tmp_path)
    with pytest.raises(ValueError, match=r"compensated has shape \(7200,\), expected \(7201,\)"):
        rp.compensation(run, comp[1:])


def test_allan_draws_the_curve_and_the_terms_the_read_off_resolved(warmup, tmp_path):
    run, _ = warmup
    result = rlgtherm.allan(run)  # the raw bias: ARW and RRW resolved, bias instability not
    fig = rp.allan(result)
    (ax,) = fig.axes
    measured = lines(ax, "measured σ(τ), overlapping, octave τ")
    np.testing.assert_array_equal(measured.get_xdata(), result["tau_s"])
    np.testing.assert_array_equal(measured.get_ydata(), result["adev_dph"])
    terms = {line.get_label().split(" ")[0]: line for line in ax.get_lines() if line.get_linestyle() == "--"}
    assert set(terms) == {"ARW", "RRW"}
    assert result["bias_instability_dph"] is None and "bias instability: not resolved (< " in fig.texts[0].get_text()
    # Each line is its term's sigma(tau): ARW N / sqrt(tau), N = 60 x the reported °/sqrt(h);
    # RRW K sqrt(tau / 3), K = the reported °/h/sqrt(h) / 60 (model/allan.cpp). 1e-12: the
    # line's few operations in numpy against the same formula here.
    for name, expected in (("ARW", lambda t: 60 * result["arw_deg_per_sqrt_h"] / np.sqrt(t)),
                           ("RRW", lambda t: result["rrw_deg_per_h_per_sqrt_h"] / 60 * np.sqrt(t / 3))):
        tau = terms[name].get_xdata()
        np.testing.assert_allclose(terms[name].get_ydata(), expected(tau), rtol=1e-12)
    assert ax.get_xscale() == ax.get_yscale() == "log"
    renders(fig, tmp_path)
    same = rp.allan(run)  # a Run: analysed with rlgtherm.allan first
    np.testing.assert_array_equal(same.axes[0].get_lines()[0].get_ydata(), result["adev_dph"])
    assert same.axes[0].get_title() == "run fixed+60: Allan deviation of bias_dph"


@pytest.fixture(scope="module")
def comparison(warmup_data):
    return rlgtherm.compare(warmup_data, fit_runs=["w-20", "w+0", "w+20", "w+40"])


def test_heldout_draws_a_panel_of_samples_and_means_per_model(comparison, tmp_path):
    fitted = [m for m in comparison["models"] if "heldout_T" in m]
    fig = rp.heldout(comparison)
    shown = [ax for ax in fig.axes if ax.get_visible()]
    assert len(shown) == len(fitted) > 1
    for ax, m in zip(shown, fitted):
        samples = lines(ax, "held-out samples")
        np.testing.assert_array_equal(samples.get_xdata(), m["heldout_T"])
        np.testing.assert_array_equal(samples.get_ydata(), m["heldout_compensated_dph"])
        means = lines(ax, "means over 1/40 of the range")
        assert 1 <= len(means.get_xdata()) <= 40
        assert ax.get_title().startswith(f"{m['label']}: ")
    renders(fig, tmp_path)
    one = rp.heldout(comparison, [fitted[-1]["label"]])
    assert len([ax for ax in one.axes if ax.get_visible()]) == 1
    with pytest.raises(ValueError, match="no fitted model 'nope' in the report"):
        rp.heldout(comparison, ["nope"])


def test_pareto_draws_the_candidates_the_front_the_target_and_the_recommended(tmp_path):
    answer = rlgtherm.plan(str(SOURCE / "tests/data/plan/verify.toml"))  # two candidates, d-optimal-3 recommended
    fig = rp.pareto(answer)
    (ax,) = fig.axes
    points = [c for c in answer["candidates"] if c["p95_abs_bias_after_dph"] is not None]
    target = lines(ax, f"target {answer['target']['p95_abs_bias_after_dph']:g} °/h")
    assert list(target.get_ydata()) == [answer["target"]["p95_abs_bias_after_dph"]] * 2
    (bars,) = ax.containers
    np.testing.assert_array_equal(bars.lines[0].get_xdata(), [c["chamber_h"] for c in points])
    np.testing.assert_array_equal(bars.lines[0].get_ydata(), [c["p95_abs_bias_after_dph"] for c in points])
    front = lines(ax, "Pareto front")
    assert min(front.get_ydata()) == min(c["p95_abs_bias_after_dph"] for c in points if c["pareto"])
    ring = lines(ax, "recommended")
    best = next(c for c in points if c["name"] == answer["recommended"])
    assert list(ring.get_xdata()) == [best["chamber_h"]] and list(ring.get_ydata()) == [best["p95_abs_bias_after_dph"]]
    assert [t.get_text() for t in ax.texts] == [str(k + 1) for k in range(len(points))]  # numbered, named in the key
    assert fig.texts[0].get_text() == "   ".join(f"{k + 1} {c['name']}" for k, c in enumerate(points))
    assert ax.get_yscale() == "log"
    renders(fig, tmp_path)


def test_without_matplotlib_the_import_says_what_to_install():
    script = ("import sys\nsys.modules['matplotlib'] = None  # as if not installed\nimport rlgtherm\n"
              "try:\n    import rlgtherm.plot\nexcept ImportError as e:\n    print(e)\n")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    assert out == "rlgtherm.plot needs matplotlib (Debian's python3-matplotlib, or pip install matplotlib)\n"
