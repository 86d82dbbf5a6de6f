"""Fixtures of the Python module's tests: the CLI (the reference the module is compared with),
the repository and small simulated data sets, made once per session."""
import json
import os
import subprocess
import threading
import time
from pathlib import Path

import pytest

import rlgtherm

SOURCE = Path(os.environ.get("RLG_SOURCE_DIR", Path(__file__).resolve().parents[2]))
BIN = os.environ.get("RLG_BIN", str(SOURCE / "build/bin/rlgtherm"))
SHORT = str(SOURCE / "tests/cli/data/short.toml")  # two 600 s runs of the default gyro


def cli(*args, status=0):
    """Runs the CLI; returns (stdout, stderr). Asserts its exit status."""
    p = subprocess.run([BIN, *map(str, args)], capture_output=True, text=True)
    assert p.returncode == status, f"rlgtherm {' '.join(map(str, args))}: exit {p.returncode}\n{p.stderr}"
    return p.stdout, p.stderr


def cli_error(*args, status):
    """The message the CLI prints for a refusal (after 'rlgtherm: error: ' or
    'rlgtherm: numerical failure: ')."""
    _, err = cli(*args, status=status)
    prefix = "rlgtherm: error: " if status == 2 else "rlgtherm: numerical failure: "
    assert err.startswith(prefix), err
    return err[len(prefix):].rstrip("\n")


@pytest.fixture(scope="session")
def warmups(tmp_path_factory):
    """Five 2 h warm-ups at 10 s after soaks at -20 ... +60 °C: enough start temperatures for
    Eq. (2) and its run-scatter errors (4 or more runs), small enough to fit in a second.
    Returns (scenario path, CSV path written by the CLI, coefficients path written by
    `rlgtherm fit -o` on the first four runs)."""
    d = tmp_path_factory.mktemp("warmups")
    runs = "".join(f'[[runs]]\nid = "w{c:+d}"\nambient = {{ profile = "constant", value_C = {c} }}\n'
                   for c in (-20, 0, 20, 40, 60))
    scenario = d / "warmups.toml"
    scenario.write_text(f'gyro = "{SOURCE}/scenarios/gyros/default.toml"\nseed = 3\n'
                        f"[defaults]\nduration_s = 7200\nsample_period_s = 10\n{runs}")
    csv = d / "warmups.csv"
    cli("simulate", scenario, "-o", csv)
    coeffs = d / "coeffs.json"
    cli("fit", csv, "--runs", "w-20,w+0,w+20,w+40", "-o", coeffs)
    return scenario, csv, coeffs


@pytest.fixture(scope="session")
def warmup_data(warmups):
    return rlgtherm.read_csv(warmups[1])


@pytest.fixture(scope="session")
def cli_coefficients(warmups):
    return json.loads(warmups[2].read_text())


@pytest.fixture
def dask_client(monkeypatch):
    """A Dask client of a local cluster of two single-threaded worker processes (skipped without
    Debian's python3-distributed). Worker processes start afresh: they find rlgtherm and
    rlgtherm_dask on the PYTHONPATH they inherit."""
    distributed = pytest.importorskip("distributed")
    import rlgtherm_dask
    where = {str(Path(rlgtherm.__file__).parents[1]), str(Path(rlgtherm_dask.__file__).parent)}  # the package's parent
    monkeypatch.setenv("PYTHONPATH", os.pathsep.join([*where, os.environ.get("PYTHONPATH", "")]))
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as cluster, distributed.Client(cluster) as client:
        yield client


def longest_python_pause(work):
    """Runs work() on a thread while this one loops in Python; returns (the loop's longest pause,
    the call's duration) in s. A call that holds the GIL pauses the loop for as long as it holds
    it; one that releases it, for Python's switch interval (5 ms) or the OS's scheduling."""
    span = {}

    def run():
        t0 = time.perf_counter()
        work()
        span["call"] = time.perf_counter() - t0

    worker = threading.Thread(target=run)
    worker.start()
    longest, last = 0.0, time.perf_counter()
    while worker.is_alive():
        now = time.perf_counter()
        longest, last = max(longest, now - last), now
    worker.join()
    return longest, span["call"]
