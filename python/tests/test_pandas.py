"""Runs and traces as pandas DataFrames (docs/python.md, "In a notebook"): Run.to_pandas,
Trace.to_pandas and Trace.from_pandas round-trip exactly (the values are copied, never
converted), a frame is checked as Run() checks columns, and `import rlgtherm` works without
pandas (Debian's python3-pandas is optional)."""
import subprocess
import sys

import numpy as np
import pytest

import rlgtherm
from conftest import SHORT

pd = pytest.importorskip("pandas")


@pytest.fixture(scope="module")
def short():
    return rlgtherm.simulate(SHORT, seed=7)  # two 600 s runs: fixed+0 and ramp


def assert_same_runs(a, b):
    assert a.ids == b.ids
    for x, y in zip(a, b):
        assert x.names == y.names
        for name in ["t_s", *x.names]:
            np.testing.assert_array_equal(x[name], y[name])  # exact: copies of the same doubles


def test_a_run_is_a_frame_of_its_columns_with_its_id(short):
    run = short["ramp"]
    frame = run.to_pandas()
    assert isinstance(frame, pd.DataFrame)
    assert list(frame.columns) == ["t_s", *run.names] and len(frame) == len(run)
    assert frame.attrs["run"] == "ramp"
    np.testing.assert_array_equal(frame["T1"].to_numpy(), run["T1"])
    frame.loc[0, "T1"] = 99.0  # a copy: the run is untouched
    assert run["T1"][0] != 99.0
    assert_same_runs(rlgtherm.Trace.from_pandas(frame.assign(T1=run["T1"])), rlgtherm.Trace([run]))


def test_a_trace_round_trips_through_its_tidy_frame(short):
    frame = short.to_pandas()
    assert list(frame.columns) == ["run", "t_s", *short[0].names]  # the tidy CSV's header
    assert list(pd.unique(frame["run"])) == short.ids and len(frame) == sum(len(r) for r in short)
    assert_same_runs(rlgtherm.Trace.from_pandas(frame), short)


def test_runs_of_different_columns_round_trip(short):
    """A frame of runs with other columns has missing values where a run lacks a column: the
    column is not that run's."""
    first = short[0]
    other = rlgtherm.Run("other", {"t_s": first.t_s, "T1": first["T1"], "bias_dph": first["bias_dph"],
                                   "P_heater_W": np.full(len(first), 2.5)})
    trace = rlgtherm.Trace([first, other])
    frame = trace.to_pandas()
    assert frame["P_heater_W"].isna().sum() == len(first) and frame["T2"].isna().sum() == len(other)
    back = rlgtherm.Trace.from_pandas(frame)
    assert back[0].names == first.names and back[1].names == ["T1", "bias_dph", "P_heater_W"]
    for x, y in zip(back, trace):
        for name in ["t_s", *y.names]:
            np.testing.assert_array_equal(x[name], y[name])


def test_a_frame_of_ones_own_makes_a_checked_run():
    t = np.arange(5.0)
    frame = pd.DataFrame({"t_s": t, "T1": 20 + t, "bias_dph": 0.1 * t})
    trace = rlgtherm.Trace.from_pandas(frame, run="mine")
    assert trace.ids == ["mine"] and trace[0].names == ["T1", "bias_dph"]
    indexed = rlgtherm.Trace.from_pandas(frame.set_index("t_s"), run="mine")  # t_s as the index
    assert_same_runs(indexed, trace)
    ints = rlgtherm.Trace.from_pandas(pd.DataFrame({"t_s": [0, 1, 2], "T1": [20, 21, 22]}), run="ints")
    assert ints[0]["T1"].dtype == np.float64 and list(ints[0]["T1"]) == [20.0, 21.0, 22.0]


def test_a_frame_is_refused_where_run_refuses_its_columns():
    t = np.arange(5.0)
    with pytest.raises(ValueError, match=r"run 'x': column 'T1' = nan at t = 2 s: not a finite number"):
        rlgtherm.Trace.from_pandas(pd.DataFrame({"t_s": t, "T1": [20, 20, np.nan, 20, 20]}), run="x")
    with pytest.raises(ValueError, match="kelvin"):
        rlgtherm.Trace.from_pandas(pd.DataFrame({"t_s": t, "T1": 293.15 + t}), run="x")
    with pytest.raises(ValueError, match="run 'x': no column 't_s'"):
        rlgtherm.Trace.from_pandas(pd.DataFrame({"T1": t}), run="x")
    with pytest.raises(ValueError, match=r"no 'run' column and no .attrs\['run'\]: give run='id'"):
        rlgtherm.Trace.from_pandas(pd.DataFrame({"t_s": t}))
    with pytest.raises(ValueError, match="has a 'run' column: its values are the run ids"):
        rlgtherm.Trace.from_pandas(pd.DataFrame({"run": "a", "t_s": t}), run="b")
    with pytest.raises(TypeError, match="expected a pandas DataFrame, got dict"):
        rlgtherm.Trace.from_pandas({"t_s": t})
    with pytest.raises(TypeError, match="column 'note'"):
        rlgtherm.Trace.from_pandas(pd.DataFrame({"t_s": t, "note": list("abcde")}), run="x")


def test_rlgtherm_imports_without_pandas_and_says_what_to_install():
    script = ("import sys\nsys.modules['pandas'] = None  # as if not installed\nimport rlgtherm\n"
              "run = rlgtherm.Run('r', {'t_s': [0.0, 1.0]})\n"
              "try:\n    run.to_pandas()\nexcept ImportError as e:\n    print(e)\n")
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout
    assert out.startswith("Run.to_pandas needs pandas (Debian's python3-pandas, or pip install pandas)")
    loaded = subprocess.run([sys.executable, "-c", "import sys, rlgtherm; print(sorted({'pandas', 'matplotlib'} & "
                             "set(sys.modules)))"], capture_output=True, text=True, check=True).stdout
    assert loaded == "[]\n"  # `import rlgtherm` imports neither
