"""Your own compensator on a population (docs/python.md, "Your own compensator on every gyro"):
population_gyros(..., compensator=fit) calls fit(calibration) per gyro and fit, and its result
on each run the fit compensates; its rows join the suite's under its name, and the summary and
rlgtherm_dask rank it beside the fitted model.

The reference is the suite's own Eq. (2): a fit that rebuilds it with rlgtherm.fit and
Compensator must give every gyro's metrics and checks exactly, not to a tolerance. The same C++
fit runs on the same runs (copies of them), its coefficients reach the Compensator as the
doubles themselves (a dict of Python floats, no decimal text between), the same causal
Compensator compensates, and the same evaluation scores the output: there is no step at which
round-off could differ, so a difference of one ulp would be a bug."""
import functools
import warnings

import numpy as np
import pytest

import rlgtherm
from conftest import SOURCE, longest_python_pause

SMALL = str(SOURCE / "tests/data/population/small.toml")  # 24 gyros, four 20-minute runs each
FIT_RUNS = ["fixed-20", "fixed+0", "fixed+20"]           # small.toml's [[fits]]
COMPENSATED = ["fixed-20", "fixed+0", "fixed+20", "fixed+40"]


def eq2py(calibration):
    """Eq. (2) as the suite fits it (pair T1, T2, joint, B0 over 120 s), in Python."""
    compensator = rlgtherm.Compensator(rlgtherm.fit(calibration, pair=("T1", "T2")))
    return compensator.compensate_run


def quiet(f, *args, **kwargs):
    """f(...) without the Compensator's warning for the +40 °C run, beyond the fitted range."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        return f(*args, **kwargs)


@pytest.fixture(scope="module")
def builtin():
    return rlgtherm.population_gyros(SMALL)


@pytest.fixture(scope="module")
def with_eq2py():
    return quiet(rlgtherm.population_gyros, SMALL, compensator=eq2py)


def own_columns(shard, names, name="eq2py"):
    """The columns of `shard` that are compensator `name`'s versions of `names` (eq2's)."""
    def theirs(n):
        run, rest = n.split(".", 1)
        return f"{run}.{name}.{rest}"
    return [shard["metric_names"].index(theirs(n)) for n in names]


def test_a_python_eq2_gives_every_gyro_the_built_in_eq2s_metrics_and_checks_exactly(builtin, with_eq2py):
    b, g = builtin, with_eq2py
    m, c = len(b["metric_names"]), len(b["check_names"])
    # The suite's own rows first, unchanged; then the compensator's, one per eq2 row.
    assert g["metric_names"][:m] == b["metric_names"] and g["check_names"][:c] == b["check_names"]
    assert len(g["metric_names"]) == 2 * m and len(g["check_names"]) == 2 * c
    np.testing.assert_array_equal(g["metrics"][:, :m], b["metrics"])
    np.testing.assert_array_equal(g["gyro"], b["gyro"])
    np.testing.assert_array_equal(g["parameters"], b["parameters"])
    # Exact (see the module's docstring): every metric of every gyro.
    np.testing.assert_array_equal(g["metrics"][:, own_columns(g, b["metric_names"])], b["metrics"])
    assert g["check_names"][c:] == [f"{n} [eq2py]" for n in b["check_names"]]  # small.toml has no best-pair check
    for key in ("check_passed", "check_value", "check_limit"):
        np.testing.assert_array_equal(g[key][:, c:], b[key])
        np.testing.assert_array_equal(g[key][:, :c], b[key])


def test_the_summary_ranks_it_beside_eq2(builtin, with_eq2py):
    alone = rlgtherm.population_summary(SMALL, builtin)
    both = rlgtherm.population_summary(SMALL, with_eq2py, compensator=eq2py)
    assert rlgtherm.population_summary(SMALL, with_eq2py, compensator="eq2py") == both  # the name is enough
    metrics = both["population"]["metrics"]
    own = [dict(r, compensator="eq2") for r in metrics if r["compensator"] == "eq2py"]
    assert [r for r in metrics if r["compensator"] == "eq2"] == alone["population"]["metrics"] == own
    checks = both["population"]["checks"]
    assert [dict(r, compensator="eq2") for r in checks if r["compensator"] == "eq2py"] == alone["population"]["checks"]
    assert both["passed"] == alone["passed"]
    # Shards with its rows are not another suite's: the summary must be told the compensator.
    with pytest.raises(ValueError, match="not this suite's .a shard of another suite, or of another compensator="):
        rlgtherm.population_summary(SMALL, with_eq2py)


def test_fit_gets_each_gyros_training_runs_and_its_result_each_compensated_run():
    calls = []

    def recorder(calibration):
        assert isinstance(calibration, rlgtherm.Trace)
        calls.append(("fit", calibration.ids, calibration[0]["T1"].copy()))

        def compensate(run):
            calls.append(("run", run.id, None))
            return run["bias_dph"] - run["bias_dph"][:120].mean()
        return compensate

    rlgtherm.population_gyros(SMALL, 3, 2, threads=1, compensator=recorder)
    assert [(kind, ids) for kind, ids, _ in calls] == [("fit", FIT_RUNS), *[("run", r) for r in COMPENSATED]] * 2
    # Each gyro's own runs: gyro i's, as simulate draws it from the suite's scenario with the suite's seed.
    assert not np.array_equal(calls[0][2], calls[5][2])


def test_the_compensator_can_keep_what_it_is_given():
    """The runs are the compensator's own copies: what it keeps is valid after the gyro is gone."""
    kept = []

    def keeper(calibration):
        kept.append(calibration)
        return lambda run: (kept.append(run), run["bias_dph"])[1]

    rlgtherm.population_gyros(SMALL, 0, 2, threads=2, compensator=keeper)
    assert len(kept) == 2 * (1 + len(COMPENSATED))
    for item in kept:
        run = item[0] if isinstance(item, rlgtherm.Trace) else item
        assert len(run) > 0 and np.isfinite(run["bias_dph"]).all()


def test_the_c_parts_run_without_the_gil():
    """Python keeps running beside population_gyros with a Python compensator: the GIL is held
    for the compensator's Python alone, and rlgtherm.fit and compensate_run release it."""
    longest, call = longest_python_pause(lambda: quiet(  # ~0.5 s
        rlgtherm.population_gyros, str(SOURCE / "scenarios/paper-population.toml"), 0, 6, threads=1, compensator=eq2py))
    # As test_population's test without a compensator: pauses are the 5 ms switch interval or a
    # busy machine's scheduling; a GIL held through the gyros would pause the loop for all of it.
    assert longest < call / 2, (longest, call)


def test_a_dask_cluster_of_two_worker_processes_runs_it_with_the_same_summary(dask_client):
    import rlgtherm_dask

    def eq2_on_workers(calibration):  # defined here, so pickled by value to the worker processes
        return rlgtherm.Compensator(rlgtherm.fit(calibration, pair=("T1", "T2"))).compensate_run

    named = ("eq2_on_workers", eq2py)  # the same function under the name the workers' rows take
    expected = rlgtherm.population_summary(SMALL, quiet(rlgtherm.population_gyros, SMALL, compensator=named),
                                           compensator=named)
    summary = rlgtherm_dask.run_population(SMALL, dask_client, shard_size=5, compensator=eq2_on_workers)
    assert summary == expected
    local = quiet(rlgtherm_dask.run_population, SMALL, shard_size=10, compensator=named)  # Dask's local threads
    assert local == expected


def test_bad_compensators_are_refused_with_what_is_wrong():
    def gyros(compensator, count=1):
        return rlgtherm.population_gyros(SMALL, 0, count, threads=1, compensator=compensator)

    with pytest.raises(ValueError, match="small.toml: a compensator named 'eq2': expected a non-empty name other than "
                                         r"a fitted model's or a plug-in's of the suite \(eq2, guo2006, poly"):
        gyros(("eq2", eq2py))
    with pytest.raises(ValueError, match="a compensator named ''"):
        gyros(("", eq2py))
    with pytest.raises(TypeError, match=r"compensator: expected a fit function or a \(name, fit\) pair, got int"):
        gyros(3)
    with pytest.raises(TypeError, match=r"a tuple must be \(name: str, fit: callable\)"):
        gyros(("x", 3))
    with pytest.raises(TypeError, match="compensator 'bad' on gyro 0: fit returned float, expected a callable"):
        gyros(("bad", lambda calibration: 1.0))
    with pytest.raises(ValueError, match=r"compensator 'short' on gyro 0, run 'fixed-20': 1200 values for its 1201 "
                                         "samples"):
        gyros(("short", lambda calibration: lambda run: run["bias_dph"][1:]))

    def nan_at_7(run):
        out = run["bias_dph"].copy()
        out[7] = np.nan
        return out
    with pytest.raises(ValueError, match=r"compensator 'nan' on gyro 0, run 'fixed-20': value 7 \(t_s = 7\): nan, not a "
                                         "finite bias"):
        gyros(("nan", lambda calibration: nan_at_7))
    with pytest.raises(ValueError, match=r"'huge' on gyro 0, run 'fixed-20': value 0 \(t_s = 0\): bias 1e\+08 °/h is "
                                         "beyond"):
        gyros(("huge", lambda calibration: lambda run: np.full(len(run), 1e8)))
    with pytest.raises(TypeError, match="compensator 'text' on gyro 0, run 'fixed-20': expected an array of numbers"):
        gyros(("text", lambda calibration: lambda run: "no"))

    # What the compensator raises reaches the caller as itself, from any thread.
    def broken(calibration):
        raise ZeroDivisionError("my fit failed")
    for threads in (1, 2):
        with pytest.raises(ZeroDivisionError, match="my fit failed"):
            rlgtherm.population_gyros(SMALL, 0, 4, threads=threads, compensator=broken)
    with pytest.raises(ValueError, match="has no __name__"):
        gyros(functools.partial(eq2py))
    with pytest.raises(TypeError, match=r"expected a fit function, a \(name, fit\) pair or a name, got int"):
        rlgtherm.population_summary(SMALL, [], compensator=5)
