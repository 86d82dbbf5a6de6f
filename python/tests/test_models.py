"""The model family from Python: fit(model=...), compare() and the Compensator with any model's
coefficients, against the CLI (docs/python.md, "Models")."""
import json

import numpy as np
import pytest

import rlgtherm
from conftest import cli, cli_error

TRAIN = ["w-20", "w+0", "w+20", "w+40"]


@pytest.mark.parametrize("args", [("px4",), ("ardupilot",), ("poly", "--order", "2", "--terms", "rate,gradient:T2"),
                                  ("poly", "--offset", "power_on", "--terms", "lag")])
def test_fit_of_each_model_equals_the_cli_fit(warmups, warmup_data, args):
    out, _ = cli("fit", warmups[1], "--runs", ",".join(TRAIN), "--model", *args, "--json")
    kwargs = {"model": args[0]}
    rest = dict(zip(args[1::2], args[2::2]))
    if "--order" in rest:
        kwargs["order"] = int(rest["--order"])
    if "--terms" in rest:
        kwargs["terms"] = rest["--terms"].split(",")
    if "--offset" in rest:
        kwargs["offset"] = rest["--offset"]
    # The same doubles: nlohmann writes the shortest text that reads back to them.
    assert rlgtherm.fit(warmup_data, runs=TRAIN, **kwargs) == json.loads(out)


def test_fit_refuses_what_the_cli_refuses(warmups, warmup_data):
    message = cli_error("fit", warmups[1], "--model", "px4", "--order", "5", status=2)
    with pytest.raises(ValueError) as e:
        rlgtherm.fit(warmup_data, model="px4", order=5)
    assert str(e.value) == message


def test_compare_equals_the_cli_compare_json(warmups, warmup_data):
    out, _ = cli("compare", warmups[1], "--fit-runs", ",".join(TRAIN), "--json")
    expected = json.loads(out)
    got = rlgtherm.compare(warmup_data, fit_runs=TRAIN)
    # The data's name differs (the CLI names the file it read); every number is the same. The
    # held-out samples (what --plot draws) are the module's alone, checked below.
    expected.pop("data"), got.pop("data")
    samples = [{k: m.pop(k) for k in ("heldout_channel", "heldout_T", "heldout_compensated_dph") if k in m}
               for m in got["models"]]
    assert got == expected
    for m, s in zip(got["models"], samples):
        if "not_applicable" in m:
            assert not s
            continue
        # The samples of the held-out runs, whole: their channel's values, and the compensated
        # bias whose RMS the report gives (summed in another order: 1e-12 relative).
        held = [warmup_data[h["run"]] for h in got["heldout"]]
        assert s["heldout_channel"] == m["coefficients_file"].get("channel", "T1")
        np.testing.assert_array_equal(s["heldout_T"], np.concatenate([r[s["heldout_channel"]] for r in held]))
        assert len(s["heldout_compensated_dph"]) == len(s["heldout_T"])
        assert np.sqrt(np.mean(s["heldout_compensated_dph"] ** 2)) == pytest.approx(m["heldout_rms_dph"], rel=1e-12)
    assert [m["label"] for m in got["models"]][0] and got["selected"]["why"]
    assert all("model" in m for m in got["models"])


def test_a_polynomial_compensator_sample_by_sample_equals_arrays_a_whole_run_and_the_cli(warmups, warmup_data, tmp_path):
    coeffs = rlgtherm.fit(warmup_data, runs=TRAIN, model="poly", offset="power_on", terms=["rate", "gradient:T2"])
    run = warmup_data["w+60"]
    t, T1, T2, b = run.t_s, run["T1"], run["T2"], run["bias_dph"]
    c = rlgtherm.Compensator(coeffs)
    assert c.channels == ["T1", "T2"] and c.pair is None and c.Ti0 is None
    one_by_one = np.array([c.update(*s) for s in zip(t, T1, T2, b)])
    assert c.b0_frozen
    c.reset()
    chunked = np.concatenate([c.update_many(t[:7], T1[:7], T2[:7], b[:7]), c.update_many(t[7:], T1[7:], T2[7:], b[7:])])
    whole = c.compensate_run(run)
    np.testing.assert_array_equal(one_by_one, chunked)
    np.testing.assert_array_equal(one_by_one, whole)
    path = tmp_path / "poly.json"
    path.write_text(json.dumps(coeffs, indent=2))
    cli("compensate", warmups[1], "--coeffs", path, "-o", tmp_path / "comp.csv")
    written = rlgtherm.read_csv(tmp_path / "comp.csv", keep_columns=["bias_comp_dph"])["w+60"]["bias_comp_dph"]
    # The CSV rounds the bias to 6 decimals: half a unit of the last, plus the double nearest to it.
    np.testing.assert_array_less(np.abs(whole - written), 0.5e-6 + 1e-12)
    with pytest.raises(ValueError, match="the model takes t_s, T1, T2, bias_dph"):
        c.update(0.0, 20.0, 1.0)
