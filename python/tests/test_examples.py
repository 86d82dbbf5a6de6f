"""The examples' code of their own (python/examples): what they claim of it holds."""
import importlib.util

import numpy as np
import pytest

import rlgtherm
from conftest import SHORT, SOURCE


@pytest.fixture(scope="module")
def first_steps():
    spec = importlib.util.spec_from_file_location("first_steps", SOURCE / "python/examples/first_steps.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # defines its functions; main() runs only as a script
    return module


def test_the_first_steps_own_compensator_is_causal(first_steps):
    """Sample k of the compensated bias uses samples 0..k only: compensating the first k samples
    of a run gives the first k values of the whole run's, for prefixes inside the B0 window and
    beyond it. (Before: np.gradient's central difference and a B0 of the whole window read ahead.)"""
    run = rlgtherm.simulate(SHORT)["ramp"]  # T1 changes from 100 s on: the rate matters
    beta = np.array([0.01, 0.5])  # any coefficients: causality does not depend on them
    prefixes = {k: rlgtherm.Run("prefix", {name: column[:k] for name, column in run.columns.items()})
                for k in (2, 3, 60, 121, 300, len(run))}
    # The matrix product may round differently for another length (1e-12 relative); a look-ahead
    # changes values by the T1 curvature's share, orders of magnitude more.
    for k, prefix in prefixes.items():
        np.testing.assert_allclose(first_steps.features(prefix), first_steps.features(run)[:k], rtol=1e-12,
                                   atol=1e-12, err_msg=f"features of the first {k} samples")
    whole = first_steps.mine(run, beta)
    for k, prefix in prefixes.items():
        np.testing.assert_allclose(first_steps.mine(prefix, beta), whole[:k], rtol=1e-12, atol=1e-12,
                                   err_msg=f"first {k} samples")
