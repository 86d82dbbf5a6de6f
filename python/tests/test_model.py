"""fit, Compensator, evaluate, allan, diagnose and gyro files against the CLI (docs/python.md)."""
import json
import sys
import warnings

import numpy as np
import pytest

import rlgtherm
from conftest import SHORT, SOURCE, cli

TRAIN = ["w-20", "w+0", "w+20", "w+40"]


def test_fit_equals_the_cli_fit_file(warmup_data, cli_coefficients):
    # Both are the same doubles: nlohmann writes the shortest text that reads back to them.
    assert rlgtherm.fit(warmup_data, pair=("T1", "T2"), runs=TRAIN) == cli_coefficients
    assert set(cli_coefficients) >= {"A", "A_stderr", "A_stderr_dof", "A_ci95_halfwidth", "T10_range_C"}


def test_fits_dict_dumped_as_json_is_a_coefficients_file_for_the_cli(warmups, warmup_data, tmp_path):
    path = tmp_path / "c.json"
    path.write_text(json.dumps(rlgtherm.fit(warmup_data, runs=TRAIN), indent=2))
    mine, _ = cli("compensate", warmups[1], "--coeffs", path, "--json")
    theirs, _ = cli("compensate", warmups[1], "--coeffs", warmups[2], "--json")
    assert mine == theirs


def test_two_stage_and_averaged_fits_equal_the_cli(warmups, warmup_data):
    out, _ = cli("fit", warmups[1], "--method", "two_stage", "--average", 60, "--json")
    assert rlgtherm.fit(warmup_data, method="two_stage", average_s=60) == json.loads(out)


def test_compensator_sample_by_sample_equals_arrays_and_the_cli(warmups, warmup_data, cli_coefficients, tmp_path):
    run = warmup_data["w+60"]
    t, Ti, Tj, b = run.t_s, run["T1"], run["T2"], run["bias_dph"]
    c = rlgtherm.Compensator(cli_coefficients)
    one_by_one = np.array([c.update(*s) for s in zip(t, Ti, Tj, b)])
    assert c.b0_frozen and c.Ti0 == Ti[0] and c.pair == ("T1", "T2")
    c.reset()
    chunked = np.concatenate([c.update_many(t[:7], Ti[:7], Tj[:7], b[:7]), c.update_many(t[7:], Ti[7:], Tj[7:], b[7:])])
    whole = c.compensate_run(run)
    np.testing.assert_array_equal(one_by_one, chunked)
    np.testing.assert_array_equal(one_by_one, whole)
    cli("compensate", warmups[1], "--coeffs", warmups[2], "-o", tmp_path / "comp.csv")
    written = rlgtherm.read_csv(tmp_path / "comp.csv", keep_columns=["bias_comp_dph"])["w+60"]["bias_comp_dph"]
    # The CSV rounds the bias to 6 decimals: half a unit of the last, plus the double nearest to it.
    np.testing.assert_array_less(np.abs(whole - written), 0.5e-6 + 1e-12)


def test_evaluate_equals_compensate_json(warmups, warmup_data, cli_coefficients, tmp_path):
    out, _ = cli("compensate", warmups[1], "--coeffs", warmups[2], "--json")
    expected = json.loads(out)["runs"]
    # compensate scores its column as the CSV writes it (1e-6 deg/h), so evaluate is handed that
    # column: read back from the file compensate writes, not recomputed here at full precision.
    cli("compensate", warmups[1], "--coeffs", warmups[2], "-o", tmp_path / "comp.csv")
    written = rlgtherm.read_csv(tmp_path / "comp.csv", keep_columns=["bias_comp_dph"])
    c = rlgtherm.Compensator(warmups[2])  # the coefficients file itself
    for run, e in zip(warmup_data, expected):
        comp = written[run.id]["bias_comp_dph"]
        # Same column up to the CSV's rounding (half a unit of the 6th decimal, plus the double nearest it).
        np.testing.assert_array_less(np.abs(c.compensate_run(run) - comp), 0.5e-6 + 1e-12)
        assert rlgtherm.evaluate(run, comp, coefficients=cli_coefficients) == e
        arrays = rlgtherm.evaluate(run.t_s, run["bias_dph"], comp, run["T1"], coefficients=cli_coefficients, run=run.id)
        assert arrays == e


def test_a_users_compensator_is_scored_like_eq2(warmups, warmup_data, tmp_path):
    """The round trip: a compensation made in numpy, scored by evaluate, written
    as a column, and analysed by the CLI's allan identically."""
    run = warmup_data["w+60"]
    t, T1, bias = run.t_s, run["T1"], run["bias_dph"]
    b0 = bias[t < t[0] + 120].mean()
    X = np.column_stack([T1 - T1[0], np.gradient(T1, t)])
    beta, *_ = np.linalg.lstsq(X, bias - b0, rcond=None)
    mine = bias - b0 - X @ beta

    scored = rlgtherm.evaluate(t, bias, mine, T1)
    # A least-squares fit on the run itself removes its mean and most of its warm-up drift.
    assert abs(scored["bias_after_dph"]) < abs(scored["bias_before_dph"])
    assert scored["stability_100s_after_dph"] < scored["stability_100s_before_dph"]
    assert scored["outside_fitted_range"] is None  # no coefficients: no fitted range
    # Identity compensation changes nothing: before and after agree exactly.
    same = rlgtherm.evaluate(t, bias, bias, T1)
    assert same["bias_after_dph"] == same["bias_before_dph"]
    assert same["stability_100s_after_dph"] == same["stability_100s_before_dph"]

    copy = rlgtherm.Run(run.id, {**run.columns})
    copy.add_column("my_comp_dph", mine)
    rlgtherm.write_csv(copy, tmp_path / "mine.csv")
    out, _ = cli("allan", tmp_path / "mine.csv", "--column", "my_comp_dph", "--json")
    expected = json.loads(out)["runs"][0]
    # The CLI analyses the column as written (6 decimals); the module analyses what it reads back.
    got = rlgtherm.allan(rlgtherm.read_csv(tmp_path / "mine.csv", keep_columns=["my_comp_dph"])[0], "my_comp_dph")
    assert set(got) == set(expected)
    for key in ("tau_s", "adev_dph"):
        np.testing.assert_array_equal(got[key], expected[key])
        got[key] = expected[key]
    assert got == expected


def test_allan_of_arrays_equals_allan_of_the_run(warmup_data):
    run = warmup_data[0]
    a, b = rlgtherm.allan(run), rlgtherm.allan(run.t_s, run["bias_dph"], run=run.id)
    np.testing.assert_array_equal(a.pop("adev_dph"), b.pop("adev_dph"))
    np.testing.assert_array_equal(a.pop("tau_s"), b.pop("tau_s"))
    assert a == b and a["sample_period_s"] == 10.0


def test_gyro_files_round_trip(tmp_path):
    g = rlgtherm.load_gyro(SOURCE / "scenarios/gyros/default.toml")
    assert g.channels[:2] == ["T1", "T2"]
    rlgtherm.save_gyro(g, tmp_path / "g.toml")
    back = rlgtherm.load_gyro(tmp_path / "g.toml")
    assert back.to_toml() == g.to_toml() == (tmp_path / "g.toml").read_text()
    # The saved gyro simulates the same trace as the scenario's own.
    a, b = rlgtherm.simulate(SHORT, seed=2), rlgtherm.simulate(SHORT, seed=2, gyro=back)
    np.testing.assert_array_equal(a[1]["bias_dph"], b[1]["bias_dph"])


def test_diagnose_equals_the_cli_report(warmups, warmup_data):
    gyro = SOURCE / "scenarios/gyros/default.toml"
    out, _ = cli("diagnose", warmups[1], "--gyro", gyro, "--max-steps", 0, "--fit-runs", ",".join(TRAIN), "--json")
    report = rlgtherm.diagnose(warmup_data, rlgtherm.load_gyro(gyro), max_steps=0, fit_runs=TRAIN)
    assert report == json.loads(out)
    assert {"cause", "baseline", "extended", "gain", "calibration", "identifiability"} <= set(report)


def test_diagnose_power_equals_the_cli_and_names_no_size_below_detection(warmups, warmup_data):
    """power=True is `--power`: every first-search candidate's 90 % sizes, the thermal and sensor
    ones, then the bias ones, the named one never below the detected one (a size no candidate
    reaches is None)."""
    gyro = SOURCE / "scenarios/gyros/default.toml"
    out, _ = cli("diagnose", warmups[1], "--gyro", gyro, "--max-steps", 1, "--fit-runs", ",".join(TRAIN), "--power",
                 "--json")
    report = rlgtherm.diagnose(warmup_data, rlgtherm.load_gyro(gyro), max_steps=1, fit_runs=TRAIN, power=True)
    assert report == json.loads(out)
    power = report["power"]
    assert power["probability"] == 0.9 and power["candidates"]
    kinds = [c["cause"].split(".")[0] for c in power["candidates"]]
    assert kinds == sorted(kinds, key=lambda k: k == "bias") and "bias" in kinds and "thermal" in kinds
    for c in power["candidates"]:
        assert c["lambda_at_start"] >= 0
        if c["named"] is not None:
            assert c["detected"] is not None and 0 < c["detected"] <= c["named"]
    with pytest.raises(ValueError, match="power is that of the first search"):
        rlgtherm.diagnose(warmup_data, rlgtherm.load_gyro(gyro), max_steps=0, power=True)


def test_diagnose_without_a_gyro_equals_the_cli_without_a_network(warmups, warmup_data):
    """gyro=None is `diagnose` without --gyro: the bias search over the measured channels."""
    out, _ = cli("diagnose", warmups[1], "--max-steps", 1, "--fit-runs", ",".join(TRAIN), "--json")
    report = rlgtherm.diagnose(warmup_data, max_steps=1, fit_runs=TRAIN)
    assert report == json.loads(out)
    assert report["calibration"]["knobs"] == [] and report["calibrated"] == {}
    assert any(n.startswith("baseline: the polynomial of order") for n in report["notes"])


def test_diagnose_releases_the_gil(warmup_data):
    """Another Python thread runs while the library works: a thread that ticks every 5 ms never
    pauses for long while diagnoses run in a second thread (with the GIL held, it would pause
    for a whole diagnosis each time)."""
    import threading
    import time

    gyro = rlgtherm.load_gyro(SOURCE / "scenarios/gyros/default.toml")
    done = threading.Event()
    calls = []

    def work():
        while sum(calls) < 1.0:  # a second of diagnoses, ~0.3 s each here
            start = time.perf_counter()
            rlgtherm.diagnose(warmup_data, gyro, max_steps=0, fit_runs=TRAIN)
            calls.append(time.perf_counter() - start)
        done.set()

    worker = threading.Thread(target=work)
    ticks = [time.perf_counter()]
    worker.start()
    while not done.is_set():
        time.sleep(0.005)
        ticks.append(time.perf_counter())
    worker.join()
    # Half the shortest call: a loaded machine may pause a thread for tens of ms, a diagnosis
    # lasts hundreds, and a held GIL would pause the ticks for all of one.
    assert max(np.diff(ticks)) < 0.5 * min(calls), (max(np.diff(ticks)), calls)


def test_compensating_outside_the_fitted_range_warns_as_the_cli_does(warmups, warmup_data, cli_coefficients):
    # The coefficients were fitted on Ti0 of -20 ... +40 °C; w+60 starts at about +60 °C.
    _, err = cli("compensate", warmups[1], "--coeffs", warmups[2])
    assert "run 'w+60': Ti0 = " in err and "is outside the fitted range" in err
    outside, inside = warmup_data["w+60"], warmup_data["w+0"]
    c = rlgtherm.Compensator(cli_coefficients)
    with pytest.warns(UserWarning, match=r"run 'w\+60': Ti0 = [0-9.]+ °C is outside the fitted range"):
        c.compensate_run(outside)
    with pytest.warns(UserWarning, match=r"Compensator: Ti0 = [0-9.]+ °C is outside the fitted range"):
        c.update(outside.t_s[0], outside["T1"][0], outside["T2"][0], outside["bias_dph"][0])
    c.reset()
    with pytest.warns(UserWarning, match="outside the fitted range"):
        c.update_many(outside.t_s, outside["T1"], outside["T2"], outside["bias_dph"])
    with pytest.warns(UserWarning, match=r"run 'w\+60': Ti0 = [0-9.]+ °C is outside the fitted range"):
        rlgtherm.evaluate(outside, c.compensate_run(outside), coefficients=cli_coefficients)
    # Inside the range: no warning, also not at later samples of the same run.
    c.reset()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        c.update_many(inside.t_s, inside["T1"], inside["T2"], inside["bias_dph"])
        c.compensate_run(inside)
        rlgtherm.evaluate(inside, c.compensate_run(inside), coefficients=cli_coefficients)


def test_warnings_point_at_the_callers_line(warmup_data, cli_coefficients):
    # Before: stacklevel 2 named the caller's caller (pytest's frame here, "sys:1" in a script).
    run = warmup_data["w+60"]  # Ti0 outside the fitted range of the first four runs
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        line = sys._getframe().f_lineno + 1
        rlgtherm.Compensator(cli_coefficients).update(run.t_s[0], run["T1"][0], run["T2"][0], run["bias_dph"][0])
        rlgtherm.evaluate(run, run["bias_dph"], coefficients=cli_coefficients)
    assert [(w.filename, w.lineno) for w in caught] == [(__file__, line), (__file__, line + 1)]
    assert all("outside the fitted range" in str(w.message) for w in caught)
