"""simulate, read_csv, write_csv, Run and Trace against the CLI's files (docs/data-format.md, docs/python.md)."""
import numpy as np
import pytest

import rlgtherm
from conftest import SHORT, SOURCE, cli, cli_error

# Decimals the CSV writer keeps (io/csv.h): temperatures 4, bias 6.
DECIMALS = {"T_amb": 4, "T1": 4, "T2": 4, "T3": 4, "T4": 4, "bias_dph": 6}


@pytest.fixture(scope="module")
def short_cli_csv(tmp_path_factory):
    path = tmp_path_factory.mktemp("short") / "short.csv"
    cli("simulate", SHORT, "--seed", 7, "-o", path)
    return path


def test_write_csv_of_simulate_is_the_cli_file_byte_for_byte(short_cli_csv, tmp_path):
    trace = rlgtherm.simulate(SHORT, seed=7)
    rlgtherm.write_csv(trace, tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == short_cli_csv.read_bytes()


def test_simulated_arrays_are_the_cli_csv_values_before_rounding(short_cli_csv):
    py = rlgtherm.simulate(SHORT, seed=7)
    csv = rlgtherm.read_csv(short_cli_csv)
    assert py.ids == csv.ids == ["fixed+0", "ramp"]
    for a, b in zip(py, csv):
        assert list(a.columns) == list(b.columns) == ["t_s", *DECIMALS]
        assert a["t_s"].dtype == np.float64
        np.testing.assert_array_equal(a.t_s, b.t_s)  # times are written exactly
        for name, decimals in DECIMALS.items():
            # The CSV holds each value rounded to its decimals: within half a unit of the last
            # one, plus 1e-12 for the double nearest to the printed decimal.
            np.testing.assert_array_less(np.abs(a[name] - b[name]), 0.5 * 10.0**-decimals + 1e-12)


def test_read_csv_then_write_csv_gives_the_same_bytes(short_cli_csv, tmp_path):
    rlgtherm.write_csv(rlgtherm.read_csv(short_cli_csv), tmp_path / "again.csv")
    assert (tmp_path / "again.csv").read_bytes() == short_cli_csv.read_bytes()


POPULATION_SCENARIO = str(SOURCE / "tests/data/population/scenario.toml")  # 24 gyros, one 600 s run


@pytest.mark.parametrize("gyro,seed", [(0, None), (17, None), (np.uint64(23), None), (5, 99)])
def test_gyro_i_of_a_population_is_the_cli_simulate_gyro_i_byte_for_byte(gyro, seed, tmp_path):
    options = ["--gyro", int(gyro)] + (["--seed", seed] if seed is not None else [])
    cli("simulate", POPULATION_SCENARIO, *options, "-o", tmp_path / "cli.csv")
    rlgtherm.write_csv(rlgtherm.simulate(POPULATION_SCENARIO, seed=seed, gyro=gyro), tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()


def test_gyros_of_a_population_differ_and_a_scenario_without_one_refuses_an_index():
    a, b = (rlgtherm.simulate(POPULATION_SCENARIO, gyro=i)[0] for i in (0, 1))
    assert not np.array_equal(a["T1"], b["T1"])
    # The CLI's refusals, with gyro=I for --gyro I.
    expected = cli_error("simulate", POPULATION_SCENARIO, "-o", "-", status=2).replace("--gyro I", "gyro=I")
    with pytest.raises(ValueError) as e:
        rlgtherm.simulate(POPULATION_SCENARIO)
    assert str(e.value).startswith(expected)
    expected = cli_error("simulate", POPULATION_SCENARIO, "--gyro", 24, "-o", "-", status=2)
    with pytest.raises(ValueError) as e:
        rlgtherm.simulate(POPULATION_SCENARIO, gyro=24)
    assert str(e.value) == expected
    expected = cli_error("simulate", SHORT, "--gyro", 1, "-o", "-", status=2).replace("--gyro", "gyro=1")
    with pytest.raises(ValueError) as e:
        rlgtherm.simulate(SHORT, gyro=1)
    assert str(e.value) == expected
    with pytest.raises(ValueError, match="gyro -1: expected the index of a gyro"):
        rlgtherm.simulate(POPULATION_SCENARIO, gyro=-1)
    with pytest.raises(TypeError, match="got bool"):
        rlgtherm.simulate(POPULATION_SCENARIO, gyro=True)
    # A Gyro instead of the scenario's is the nominal one, population or not.
    nominal = rlgtherm.load_gyro(SOURCE / "scenarios/gyros/default.toml")
    assert len(rlgtherm.simulate(POPULATION_SCENARIO, gyro=nominal)[0]) == 601


def test_the_seed_is_used():
    a, b = rlgtherm.simulate(SHORT, seed=7), rlgtherm.simulate(SHORT, seed=8)
    assert not np.array_equal(a[0]["bias_dph"], b[0]["bias_dph"])
    np.testing.assert_array_equal(a[0]["bias_dph"], rlgtherm.simulate(SHORT, seed=7)[0]["bias_dph"])


def test_columns_are_read_only_views_of_the_run():
    trace = rlgtherm.simulate(SHORT, seed=7)
    run = trace["ramp"]
    assert np.shares_memory(run["T1"], run.columns["T1"])
    assert np.shares_memory(run.t_s, trace[1]["t_s"])
    assert not run["T1"].flags.writeable
    with pytest.raises(ValueError):
        run["T1"][0] = 1.0
    # A view keeps its trace alive.
    view = rlgtherm.simulate(SHORT, seed=7)[0]["bias_dph"]
    assert view.shape == (601,) and np.isfinite(view).all()  # 0 ... 600 s


def test_runs_made_in_python_are_written_by_the_cli_writer(tmp_path):
    t = np.arange(5.0)
    run = rlgtherm.Run("a", {"t_s": t, "T1": 20.0 + 0.01 * t, "bias_dph": np.full(5, 0.5)})
    run.add_column("my_comp_dph", np.zeros(5))
    assert run.names == ["T1", "bias_dph", "my_comp_dph"] and len(run) == 5
    rlgtherm.write_csv(rlgtherm.Trace([run], comments=["made in Python"]), tmp_path / "a.csv")
    assert (tmp_path / "a.csv").read_text().splitlines()[:3] == [
        "# made in Python", "run,t_s,T1,bias_dph,my_comp_dph", "a,0,20.0000,0.500000,0.000000"]
    back = rlgtherm.read_csv(tmp_path / "a.csv", keep_columns=["my_comp_dph"])
    np.testing.assert_array_equal(back["a"]["T1"], run["T1"])


def test_runs_made_in_python_are_checked_as_the_reader_checks_a_file():
    t = np.arange(3.0)
    with pytest.raises(ValueError, match="run 'a': no column 't_s'"):
        rlgtherm.Run("a", {"T1": t})
    with pytest.raises(ValueError, match=r"column 'T1' = nan at t = 1 s: not a finite number"):
        rlgtherm.Run("a", {"t_s": t, "T1": np.array([1.0, np.nan, 2.0])})
    with pytest.raises(ValueError, match="time does not increase"):
        rlgtherm.Run("a", {"t_s": np.array([0.0, 2.0, 1.0])})
    with pytest.raises(ValueError, match="column 'T1' has 2 values, t_s has 3"):
        rlgtherm.Run("a", {"t_s": t, "T1": t[:2]})
    run = rlgtherm.Run("a", {"t_s": t, "T1": t})
    with pytest.raises(ValueError, match="temperature 200 °C"):
        run.add_column("T2", np.array([0.0, 200.0, 0.0]))
    assert run.names == ["T1"]  # a refused column leaves the run as it was


def test_unknown_run_and_column():
    trace = rlgtherm.simulate(SHORT, seed=7)
    with pytest.raises(KeyError, match=r"no run .nope. in the data \(runs: fixed\+0, ramp\)"):
        trace["nope"]
    with pytest.raises(KeyError, match="has no column 'T9'"):
        trace[0]["T9"]
    with pytest.raises(IndexError):
        trace[2]


def test_a_slice_of_a_trace_is_a_trace_of_copies_and_a_bad_index_a_type_error():
    # Before: data[1:3] raised pybind11's "Unable to cast Python instance to C++ type".
    trace = rlgtherm.simulate(SHORT)
    part = trace[1:]
    assert isinstance(part, rlgtherm.Trace) and part.ids == trace.ids[1:] and part.comments == trace.comments
    np.testing.assert_array_equal(part[0]["T1"], trace[1]["T1"])
    part[0].add_column("mine_dph", np.zeros(len(part[0])))
    assert "mine_dph" not in trace[1]  # a copy: the original run is untouched
    assert trace[::-1].ids == trace.ids[::-1] and trace[5:].ids == []
    with pytest.raises(TypeError, match="run index: expected an int, a run id or a slice, got float"):
        trace[1.0]
