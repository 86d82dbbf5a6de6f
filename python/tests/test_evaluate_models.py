"""evaluate(coefficients=...) takes every model fit writes and equals `rlgtherm compensate --json`
(it refused all but Eq. (2), naming line 39 of a dict the user never saw)."""
import json

import numpy as np

import pytest

import rlgtherm
from conftest import cli

TRAIN = ["w-20", "w+0", "w+20", "w+40"]

MODELS = [
    {},  # Eq. (2)
    {"model": "px4"},
    {"model": "ardupilot"},
    {"model": "poly", "order": 2, "terms": ["rate", "gradient:T2"]},
    {"model": "poly", "offset": "power_on", "terms": ["lag"]},
    {"model": "poly", "channel": "T2", "terms": ["rate"]},  # (warm-ups never cool: no hysteresis term fits)
    {"model": "poly", "order": 1, "terms": ["T1*(T2-T1)"]},
    {"model": "poly", "order": 2, "beyond_range": "extrapolate"},
    {"model": "auto"},
]


@pytest.mark.parametrize("kwargs", MODELS, ids=lambda k: "-".join(f"{v}" for v in k.values()) or "guo2006")
def test_evaluate_of_every_model_equals_compensate(warmups, warmup_data, tmp_path, kwargs):
    coeffs = rlgtherm.fit(warmup_data, runs=TRAIN, **kwargs)
    path = tmp_path / "coeffs.json"
    path.write_text(json.dumps(coeffs, indent=2))
    out, _ = cli("compensate", warmups[1], "--coeffs", path, "--json")
    by_run = {r["run"]: r for r in json.loads(out)["runs"]}
    # compensate scores its column as the CSV writes it (1e-6 °/h): evaluate is handed that column.
    cli("compensate", warmups[1], "--coeffs", path, "-o", tmp_path / "comp.csv")
    written = rlgtherm.read_csv(tmp_path / "comp.csv", keep_columns=["bias_comp_dph"])
    c = rlgtherm.Compensator(coeffs)
    for run in warmup_data:
        comp = written[run.id]["bias_comp_dph"]
        c.reset()
        # The Compensator's column is compensate's, up to the CSV's rounding (half a unit of the
        # 6th decimal, plus the double nearest it).
        np.testing.assert_array_less(np.abs(c.compensate_run(run) - comp), 0.5e-6 + 1e-12)
        assert rlgtherm.evaluate(run, comp, coefficients=coeffs) == by_run[run.id]
        assert rlgtherm.evaluate(run, comp, coefficients=str(path)) == by_run[run.id]  # a file reads as the dict


def test_the_arrays_form_takes_a_one_channel_model_and_refuses_a_model_of_two(warmup_data):
    run = warmup_data["w+60"]
    one = rlgtherm.fit(warmup_data, runs=TRAIN, model="poly", terms=["rate"])
    comp = rlgtherm.Compensator(one).compensate_run(run)
    arrays = rlgtherm.evaluate(run.t_s, run["bias_dph"], comp, run["T1"], coefficients=one, run=run.id)
    assert arrays == rlgtherm.evaluate(run, comp, coefficients=one)
    two = rlgtherm.fit(warmup_data, runs=TRAIN, model="poly", terms=["gradient:T2"])
    with pytest.raises(ValueError, match="the model reads T1, T2 and the arrays form takes one temperature"):
        rlgtherm.evaluate(run.t_s, run["bias_dph"], comp, run["T1"], coefficients=two)
