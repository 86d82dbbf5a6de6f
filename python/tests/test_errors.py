"""Errors: ValueError with the CLI's message for bad input, rlgtherm.NumericalError (an
ArithmeticError) for numerical failure (docs/cli.md, docs/python.md)."""
import re

import numpy as np
import pytest

import rlgtherm
from conftest import SOURCE, cli, cli_error

CLI_DATA = SOURCE / "tests/cli/data"


def test_numerical_error_is_an_arithmetic_error():
    assert issubclass(rlgtherm.NumericalError, ArithmeticError)


def test_missing_data_file_is_a_value_error_naming_it(tmp_path):
    path = tmp_path / "nope.csv"
    expected = cli_error("fit", path, status=2)
    assert "nope.csv" in expected
    with pytest.raises(ValueError) as e:
        rlgtherm.read_csv(path)
    assert str(e.value) == expected
    with pytest.raises(ValueError) as e:
        rlgtherm.fit(str(path))
    assert str(e.value) == expected


def test_missing_scenario_is_a_value_error_naming_it():
    path = CLI_DATA / "nope.toml"
    expected = cli_error("simulate", path, "-o", "-", status=2)
    with pytest.raises(ValueError, match="nope.toml: scenario file not found") as e:
        rlgtherm.simulate(str(path))
    assert str(e.value) == expected


def test_solver_failure_is_a_numerical_error():
    path = CLI_DATA / "solver_failure.toml"
    expected = cli_error("simulate", path, "-o", "-", status=3)
    with pytest.raises(rlgtherm.NumericalError, match="CV_TOO_MUCH_WORK") as e:
        rlgtherm.simulate(str(path))
    assert str(e.value) == expected


@pytest.fixture(scope="module")
def one_ambient(tmp_path_factory):
    path = tmp_path_factory.mktemp("bad") / "one_ambient.csv"
    cli("simulate", CLI_DATA / "one_ambient.toml", "-o", path)
    return path


def test_unidentifiable_fit_is_a_numerical_error_with_the_cli_message(one_ambient):
    expected = cli_error("fit", one_ambient, status=3)
    assert "one_ambient.csv" in expected  # the CLI names the file; so does the module
    with pytest.raises(rlgtherm.NumericalError) as e:
        rlgtherm.fit(rlgtherm.read_csv(one_ambient))
    assert str(e.value) == expected
    with pytest.raises(ArithmeticError):
        rlgtherm.fit(str(one_ambient))


def test_bad_fit_arguments_are_value_errors_with_the_cli_messages(warmups, warmup_data):
    csv = warmups[1]
    with pytest.raises(ValueError) as e:
        rlgtherm.fit(warmup_data, pair=("T1", "T9"))
    assert str(e.value) == cli_error("fit", csv, "--pair", "T1,T9", status=2)
    with pytest.raises(ValueError) as e:
        rlgtherm.fit(warmup_data, runs=["nope"])
    assert str(e.value) == cli_error("fit", csv, "--runs", "nope", status=2)
    with pytest.raises(ValueError, match=r"pair \(T1, T1\): the same channel twice") as e:
        rlgtherm.fit(warmup_data, pair=("T1", "T1"))  # was a NumericalError about coefficient A30
    assert str(e.value) == cli_error("fit", csv, "--pair", "T1,T1", status=2)
    with pytest.raises(ValueError, match="method 'lsq': expected joint or two_stage"):
        rlgtherm.fit(warmup_data, method="lsq")


def test_bad_coefficients_are_value_errors(cli_coefficients):
    bad = dict(cli_coefficients, model=5)
    with pytest.raises(ValueError, match=r"coefficients:\d+: key 'model': expected a string, found 5"):
        rlgtherm.Compensator(bad)
    with pytest.raises(ValueError, match="coeffs_overflow.json:5:14: not valid JSON"):
        rlgtherm.Compensator(str(CLI_DATA / "coeffs_overflow.json"))


def test_evaluate_refuses_an_averaging_time_below_the_sample_period(warmup_data):
    run = warmup_data[0]
    with pytest.raises(ValueError, match="averaging time 1 s is below the 10 s sample period"):
        rlgtherm.evaluate(run, run["bias_dph"], averaging_s=1.0)


def test_short_record_for_allan_names_the_run():
    with pytest.raises(ValueError, match="run 'x': 10 samples are too few for an Allan deviation"):
        rlgtherm.allan(np.arange(10.0), np.zeros(10), run="x")


def test_unknown_diagnose_option_is_a_type_error(warmup_data):
    with pytest.raises(TypeError, match="unexpected keyword argument 'max_step'"):
        rlgtherm.diagnose(warmup_data, str(SOURCE / "scenarios/gyros/default.toml"), max_step=0)


def test_gyro_file_errors_name_the_file(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('name = "x"\nnot_a_key = 1\n')
    with pytest.raises(ValueError, match="bad.toml"):
        rlgtherm.load_gyro(bad)


def test_evaluate_refuses_a_nan_or_inf_naming_the_value_and_its_time(warmup_data):
    # One non-finite value would make every metric NaN, which the dict would carry as None.
    run = warmup_data["w+0"]
    for bad in (np.nan, np.inf):
        comp = np.array(run["bias_dph"])
        comp[17] = bad
        with pytest.raises(ValueError, match=rf"run 'w\+0': compensated\[17\] is {bad} \(at t_s = 170\)"):
            rlgtherm.evaluate(run, comp)
        with pytest.raises(ValueError, match=rf"compensated\[17\] is {bad}"):
            rlgtherm.evaluate(run.t_s, run["bias_dph"], comp, run["T1"], run=run.id)
    bias = np.array(run["bias_dph"])
    bias[3] = np.nan
    with pytest.raises(ValueError, match=r"bias_dph\[3\] is nan"):
        rlgtherm.evaluate(run.t_s, bias, run["bias_dph"], run["T1"])


def test_write_csv_of_runs_with_different_columns_names_the_output_not_the_scenario(tmp_path):
    trace = rlgtherm.simulate(CLI_DATA / "short.toml")
    trace[0].add_column("mine_dph", np.zeros(len(trace[0])))
    out = tmp_path / "out.csv"
    expected = (re.escape(f"write_csv {out}: run '{trace[1].id}' has columns ") + ".* but the first run, "
                + re.escape(f"'{trace[0].id}', has ") + ".*mine_dph")
    with pytest.raises(ValueError, match=expected) as e:
        rlgtherm.write_csv(trace, out)
    assert "short.toml" not in str(e.value)
    assert not out.exists()


def test_compensator_refuses_a_nan_in_the_b0_window_and_feeds_nothing_of_that_call(warmup_data, cli_coefficients):
    # Before: the NaN entered B0's running mean and every later output was NaN, silently.
    run = warmup_data["w+0"]
    t, Ti, Tj, b = run.t_s, run["T1"], run["T2"], np.array(run["bias_dph"])
    b[5] = np.nan  # t = 50 s, inside the 120 s window
    c = rlgtherm.Compensator(cli_coefficients)
    first = c.update_many(t[:3], Ti[:3], Tj[:3], b[:3])
    with pytest.raises(ValueError, match=r"update_many: sample 2: bias_dph = nan at t_s = 50 s: not a finite number; "
                                         r"no sample of this call was fed"):
        c.update_many(t[3:], Ti[3:], Tj[3:], b[3:])
    # The compensator is where the refused call found it: the rest of the run, the NaN left
    # out, continues it exactly as a fresh compensator fed the same samples.
    keep = np.arange(len(t)) != 5
    rest = c.update_many(t[3:][keep[3:]], Ti[3:][keep[3:]], Tj[3:][keep[3:]], b[3:][keep[3:]])
    fresh = rlgtherm.Compensator(cli_coefficients).update_many(t[keep], Ti[keep], Tj[keep], b[keep])
    np.testing.assert_array_equal(np.concatenate([first, rest]), fresh)
    assert np.isfinite(fresh).all()


def test_compensator_refuses_a_nan_or_kelvin_temperature_at_power_on(warmup_data, cli_coefficients):
    run = warmup_data["w+0"]
    c = rlgtherm.Compensator(cli_coefficients)
    with pytest.raises(ValueError, match=r"update: T1 = nan at t_s = 0 s: not a finite number; the sample was not fed"):
        c.update(0.0, np.nan, run["T2"][0], run["bias_dph"][0])
    with pytest.raises(ValueError, match=r"T2 = 293.15 at t_s = 0 s: .*kelvin\?"):
        c.update(0.0, 20.0, 293.15, 0.0)
    with pytest.raises(ValueError, match=r"bias_dph = 100000000 at t_s = 0 s: bias 1e\+08 °/h is beyond"):
        c.update(0.0, 20.0, 20.0, 1e8)
    # Nothing was fed: the first sample accepted is the power-on.
    assert np.isfinite(c.update(0.0, run["T1"][0], run["T2"][0], run["bias_dph"][0]))
    assert c.Ti0 == run["T1"][0]


def test_compensator_refuses_time_that_does_not_increase(warmup_data, cli_coefficients):
    run = warmup_data["w+0"]
    t, Ti, Tj, b = run.t_s, run["T1"], run["T2"], run["bias_dph"]
    c = rlgtherm.Compensator(cli_coefficients)
    c.update_many(t[:10], Ti[:10], Tj[:10], b[:10])
    with pytest.raises(ValueError, match=r"update: t_s = 50 s: time does not increase \(the sample before was at 90 s\)"):
        c.update(50.0, Ti[10], Tj[10], b[10])
    with pytest.raises(ValueError, match=r"update_many: sample 1: t_s = 100 s: time does not increase"):
        c.update_many(t[[10, 10]], Ti[[10, 10]], Tj[[10, 10]], b[[10, 10]])
    c.reset()  # a new run may start at any time
    assert np.isfinite(c.update(0.0, Ti[0], Tj[0], b[0]))


def test_evaluate_refuses_what_run_refuses_kelvin_1e8_and_time_going_back(warmup_data):
    # Before: the arrays were scored as given (a bias of 1e8 °/h, temperatures in kelvin).
    run = warmup_data["w+0"]
    t, bias, T1 = run.t_s, run["bias_dph"], run["T1"]
    with pytest.raises(ValueError, match=r"run 'run': column 'T1' = 273.15 at t = 0 s: .* \(kelvin\?") as e:
        rlgtherm.evaluate(t, bias, bias, T1 + 273.15)
    with pytest.raises(ValueError) as from_run:
        rlgtherm.Run("run", {"t_s": t, "T1": T1 + 273.15, "bias_dph": bias})
    assert str(e.value) == str(from_run.value)  # the same refusal as Run()'s
    with pytest.raises(ValueError, match=r"column 'bias_dph' = 100000000 at t = 0 s: bias 1e\+08 °/h is beyond"):
        rlgtherm.evaluate(t, np.full(len(t), 1e8), bias, T1)
    with pytest.raises(ValueError, match=r"compensated\[0\] = 100000000 at t_s = 0: bias 1e\+08 °/h is beyond"):
        rlgtherm.evaluate(run, np.full(len(t), 1e8))
    with pytest.raises(ValueError, match=r"run 'run': t = 7190 s: time does not increase"):
        rlgtherm.evaluate(t[::-1], bias, bias, T1)


def test_a_seed_out_of_range_is_a_value_error_and_not_an_int_a_type_error():
    # Before: pybind11's "incompatible function arguments" with the raw signature.
    suite = str(SOURCE / "tests/data/population/small.toml")
    for call in (lambda s: rlgtherm.simulate(CLI_DATA / "short.toml", seed=s),
                 lambda s: rlgtherm.population_gyros(suite, 0, 1, seed=s),
                 lambda s: rlgtherm.population_summary(suite, [], seed=s)):
        with pytest.raises(ValueError, match=r"^seed -1: expected an integer from 0 to 18446744073709551615$"):
            call(-1)
        with pytest.raises(ValueError, match=r"^seed 18446744073709551616: expected an integer from 0 to"):
            call(2**64)
        with pytest.raises(TypeError, match=r"^seed: expected an int or None, got str$"):
            call("1")
    top = rlgtherm.simulate(CLI_DATA / "short.toml", seed=np.uint64(2**64 - 1))  # numpy ints are ints
    assert top.comments[0].endswith("--seed 18446744073709551615")


def test_simulate_takes_a_gyro_files_path_as_diagnose_does():
    # Before: TypeError (only a Gyro object).
    path = SOURCE / "scenarios/gyros/default.toml"
    by_path = rlgtherm.simulate(CLI_DATA / "short.toml", gyro=path)
    by_object = rlgtherm.simulate(CLI_DATA / "short.toml", gyro=rlgtherm.load_gyro(path))
    np.testing.assert_array_equal(by_path[0]["T1"], by_object[0]["T1"])
    with pytest.raises(ValueError, match="nope.toml"):
        rlgtherm.simulate(CLI_DATA / "short.toml", gyro=CLI_DATA / "nope.toml")
