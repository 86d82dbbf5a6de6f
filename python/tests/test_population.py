"""Population suites from Python (docs/results.md, Populations, docs/python.md "Populations"): shards of
population_gyros against the CLI's per-gyro CSV, population_summary against `validate --json`,
the same summary for any split, order, thread count or Dask cluster, and bad shards refused.

Every comparison is exact: the module and the CLI run the same C++ on the same gyros (gyro i's
parameters and noise come from the suite seed and i alone), the CSV and JSON write the shortest
decimals that read back to the same double, and the summary does not depend on the order its
gyros arrive in. A difference of one ulp would be a bug, not noise."""
import csv
import json
import subprocess

import numpy as np
import pytest

import rlgtherm
from conftest import BIN, SOURCE, cli, longest_python_pause

SMALL = str(SOURCE / "tests/data/population/small.toml")  # 24 gyros, four 20-minute runs each


def validate_json(suite, *args):
    """`rlgtherm validate SUITE --json`, parsed; its exit status says whether it passed."""
    p = subprocess.run([BIN, "validate", suite, "--json", *map(str, args)], capture_output=True, text=True)
    result = json.loads(p.stdout)
    assert p.returncode == (0 if result["passed"] else 4), p.stderr
    return result


@pytest.fixture(scope="module")
def cli_summary():
    return validate_json(SMALL)


@pytest.fixture(scope="module")
def small_gyros():
    return rlgtherm.population_gyros(SMALL)


@pytest.fixture(scope="module")
def small_summary(small_gyros):
    return rlgtherm.population_summary(SMALL, [small_gyros])


def assert_same_shards(a, b):
    assert a.keys() == b.keys()
    for key in a:
        if isinstance(a[key], np.ndarray):
            assert a[key].dtype == b[key].dtype and a[key].shape == b[key].shape, key
            assert np.array_equal(a[key], b[key], equal_nan=a[key].dtype.kind == "f"), key
        else:
            assert a[key] == b[key], key


def test_population_count_reads_the_suite_file():
    assert rlgtherm.population_count(SMALL) == 24


def test_the_gyros_are_the_cli_per_gyro_csv(small_gyros, cli_summary, tmp_path):
    rows = tmp_path / "gyros.csv"
    cli("validate", SMALL, "--gyros", rows, status=0 if cli_summary["passed"] else 4)
    with open(rows) as f:
        header, *body = list(csv.reader(f))
    g = small_gyros
    p, m = len(g["parameter_names"]), len(g["metric_names"])
    assert header == ["gyro", "seed", *g["parameter_names"], *g["metric_names"], "checks_failed"]
    assert g["gyro"].dtype == np.uint64 and g["seed"].dtype == np.uint64 and g["check_passed"].dtype == bool
    assert g["parameters"].shape == (24, p) and g["metrics"].shape == (24, m)
    assert g["check_passed"].shape == g["check_value"].shape == g["check_limit"].shape == (24, len(g["check_names"]))
    table = np.array(body, dtype=float)
    assert np.array_equal(g["gyro"], np.arange(24, dtype=np.uint64))
    assert [int(r[1]) for r in body] == g["seed"].tolist()  # as ints: a uint64 seed does not fit a double
    assert np.array_equal(g["parameters"], table[:, 2:2 + p])
    assert np.array_equal(g["metrics"], table[:, 2 + p:2 + p + m])
    assert np.array_equal((~g["check_passed"]).sum(axis=1), table[:, -1])
    # A check without a number (none in small.toml, whose checks are all bias limits) would be NaN.
    assert np.isfinite(g["check_value"]).all() and np.isfinite(g["check_limit"]).all()
    assert ((g["check_value"] <= g["check_limit"]) == g["check_passed"]).all()


def test_the_summary_of_all_gyros_is_validate_json(small_summary, cli_summary):
    assert small_summary == cli_summary
    assert small_summary["population"]["gyros"] == 24


def test_shards_in_any_order_give_the_same_summary(small_summary):
    first, rest = rlgtherm.population_gyros(SMALL, 0, 10), rlgtherm.population_gyros(SMALL, 10, 14)
    assert rlgtherm.population_summary(SMALL, [rest, first]) == small_summary
    assert rlgtherm.population_summary(SMALL, (first, rest)) == small_summary


def test_threads_do_not_change_the_arrays(small_gyros):
    assert_same_shards(rlgtherm.population_gyros(SMALL, threads=1), small_gyros)  # small_gyros: one per core
    assert_same_shards(rlgtherm.population_gyros(SMALL, 3, 9, threads=2), rlgtherm.population_gyros(SMALL, 3, 9, threads=1))


def test_the_gil_is_released_while_gyros_run():
    """Python keeps running beside population_gyros: the longest pause of a Python loop during
    the call is far shorter than the call. Held, the GIL would pause the loop for all of it."""
    longest, call = longest_python_pause(  # ~0.3 s
        lambda: rlgtherm.population_gyros(str(SOURCE / "scenarios/paper-population.toml"), 0, 6, threads=1))
    # Released, pauses are Python's thread switch interval (5 ms) or the OS's scheduling on a
    # busy machine (tens of ms); half the call leaves room for both and still fails a held GIL.
    assert longest < call / 2, (longest, call)


def test_a_seed_gives_the_summary_of_validate_seed():
    summary = rlgtherm.population_summary(SMALL, rlgtherm.population_gyros(SMALL, seed=12), seed=12)
    assert summary == validate_json(SMALL, "--seed", 12)


def test_a_dask_cluster_of_two_worker_processes_gives_the_same_summary(small_summary, dask_client):
    import rlgtherm_dask
    summary = rlgtherm_dask.run_population(SMALL, dask_client, shard_size=5)  # 5 shards, the last of 4
    assert summary == small_summary
    ran_on = dask_client.run(lambda: __import__("rlgtherm").__file__)
    assert len(ran_on) == 2  # both workers imported the module


def test_dask_shards_cover_the_gyros_once():
    import rlgtherm_dask
    assert rlgtherm_dask.shards(24, 5) == [(0, 5), (5, 5), (10, 5), (15, 5), (20, 4)]
    assert rlgtherm_dask.shards(10, 4, first=3) == [(3, 4), (7, 4), (11, 2)]
    with pytest.raises(ValueError, match="shard_size 0"):
        rlgtherm_dask.shards(10, 0)


@pytest.fixture(scope="module")
def other_suite(tmp_path_factory):
    """small.toml with another spread: the same runs and checks, other parameter columns."""
    text = (SOURCE / "tests/data/population/small.toml").read_text()
    text = text.replace('"short-fixed.toml"', f'"{SOURCE}/tests/data/population/short-fixed.toml"')
    text = text[:text.index("[[population.spread]]")] + (
        '[[population.spread]]\nparameter = "bias.b0_dph"\ndistribution = "normal"\nsigma = 0.3\n')
    path = tmp_path_factory.mktemp("other") / "other.toml"
    path.write_text(text)
    return str(path)


def test_bad_shards_are_value_errors(small_gyros, other_suite):
    summary = rlgtherm.population_summary
    with pytest.raises(ValueError, match="gyro 0 was added twice"):
        summary(SMALL, [small_gyros, rlgtherm.population_gyros(SMALL, 0, 1)])
    with pytest.raises(ValueError, match=r"shard 0: its parameter_names are not this suite's"):
        summary(SMALL, [rlgtherm.population_gyros(other_suite, 0, 1)])
    cut = dict(small_gyros, metrics=small_gyros["metrics"][:, :-1])
    with pytest.raises(ValueError, match=r"shard 1: 'metrics' has shape \(24, \d+\), expected \(24, \d+\)"):
        summary(SMALL, [rlgtherm.population_gyros(SMALL, 0, 0), cut])
    with pytest.raises(ValueError, match=r"'seed' has shape \(23\), expected \(24,\)"):
        summary(SMALL, dict(small_gyros, seed=small_gyros["seed"][1:]))
    with pytest.raises(ValueError, match="shard 0: 'metric_names' is not a list of names"):
        summary(SMALL, dict(small_gyros, metric_names=5))
    with pytest.raises(ValueError, match="shard 0: no 'check_limit'"):
        summary(SMALL, [{k: v for k, v in small_gyros.items() if k != "check_limit"}])
    with pytest.raises(ValueError, match=r"gyro 0 has seed \d+, but this suite \(seed 11\) gives it \d+"):
        summary(SMALL, rlgtherm.population_gyros(SMALL, 0, 1, seed=12))
    last = rlgtherm.population_gyros(SMALL, 23, 1)
    with pytest.raises(ValueError, match="gyro 24 is not in its population of 24"):
        summary(SMALL, dict(last, gyro=last["gyro"] + 1))
    with pytest.raises(ValueError, match="no gyro to summarize"):
        summary(SMALL, [])


def test_bad_arguments_are_value_errors_with_the_cli_messages(tmp_path):
    with pytest.raises(ValueError, match=r"small.toml: gyros 20..29 are not all in a population of 24"):
        rlgtherm.population_gyros(SMALL, 20, 10)
    with pytest.raises(ValueError, match="first gyro 25 is beyond the population of 24"):
        rlgtherm.population_gyros(SMALL, 25)
    with pytest.raises(ValueError, match="threads -1: expected 0"):
        rlgtherm.population_gyros(SMALL, threads=-1)
    plain = str(SOURCE / "tests/data/population/short-fixed.toml")
    not_population = tmp_path / "plain.toml"
    not_population.write_text(f'scenarios = ["{plain}"]\n[[fits]]\nname = "f"\npair = ["T1", "T2"]\n'
                              'runs = ["fixed-20", "fixed+0", "fixed+20"]\ncompensate = ["fixed+40"]\n')
    for call in (rlgtherm.population_count, rlgtherm.population_gyros):
        with pytest.raises(ValueError, match="not a population suite: it has no \\[population\\] table"):
            call(str(not_population))
    missing = SOURCE / "tests/data/population/nope.toml"
    _, err = cli("validate", missing, status=2)
    with pytest.raises(ValueError) as e:
        rlgtherm.population_summary(str(missing), [])
    assert err == f"rlgtherm: error: {e.value}\n"
