"""import_columns against `rlgtherm import columns` (docs/cli.md, "import"): the same bytes once
written, and the same refusals with the same messages."""
import pytest

import rlgtherm
from conftest import SOURCE, cli, cli_error

IMU = str(SOURCE / "data/imu-thermal-cycle/imu_raw_data.csv")  # tab-separated, time in µs, rate in °/s


@pytest.mark.parametrize("options,kwargs", [
    (["--time", "timestamp:us", "--temp", "imu.temperature", "--rate", "imu.gyro.x:dps"],
     dict(time="timestamp:us", temp=["imu.temperature"], rate="imu.gyro.x:dps")),
    (["--time", "timestamp:us", "--temp", "imu.temperature,imu.acc.z", "--rate", "imu.gyro.z:radps", "--run", "imu-z",
      "--split-at", "1000,2500.5"],
     dict(time="timestamp:us", temp="imu.temperature,imu.acc.z", rate="imu.gyro.z:radps", run="imu-z",
          split_at=[1000, 2500.5])),
])
def test_import_columns_writes_the_commands_bytes(options, kwargs, tmp_path):
    cli("import", "columns", IMU, *options, "-o", tmp_path / "cli.csv")
    trace = rlgtherm.import_columns(IMU, **kwargs)
    rlgtherm.write_csv(trace, tmp_path / "py.csv")
    assert (tmp_path / "py.csv").read_bytes() == (tmp_path / "cli.csv").read_bytes()
    assert trace.comments == [trace.comments[0]]
    assert trace.comments[0].startswith("imported by rlgtherm import columns from imu_raw_data.csv: t_s = timestamp (us)")
    assert trace[0].names[-1] == "bias_dph" and trace[0].names[0] == "T1"


@pytest.mark.parametrize("options,kwargs", [
    (["--time", "timestamp"], dict(time="timestamp")),                          # no unit
    (["--rate", "imu.gyro.x"], dict(rate="imu.gyro.x")),                        # no unit
    (["--rate", "imu.gyro.x:deg"], dict(rate="imu.gyro.x:deg")),                # unknown unit
    (["--temp", "nope"], dict(temp=["nope"])),                                  # no such column
    (["--split-at", "100,50"], dict(split_at=[100, 50])),                       # not increasing
    (["--run", "a,b"], dict(run="a,b")),                                        # not a run id
])
def test_import_columns_refuses_what_the_command_refuses_with_its_message(options, kwargs):
    given = {"--time": "timestamp:us", "--temp": "imu.temperature", "--rate": "imu.gyro.x:dps"}
    given.update(dict(zip(options[::2], options[1::2])))
    args = [a for k, v in given.items() for a in (k, v)]
    expected = cli_error("import", "columns", IMU, *args, "-o", "-", status=2)
    with pytest.raises(ValueError) as e:
        rlgtherm.import_columns(IMU, **{**dict(time="timestamp:us", temp=["imu.temperature"], rate="imu.gyro.x:dps"),
                                       **kwargs})
    assert str(e.value) == expected


def test_a_missing_log_is_a_value_error_naming_it():
    with pytest.raises(ValueError, match="nope.csv"):
        rlgtherm.import_columns(SOURCE / "nope.csv", time="t:s", temp=["T"], rate="r:dph")


def test_a_log_that_looks_like_fahrenheit_warns_as_the_command_does(tmp_path):
    log = tmp_path / "chamber_f.csv"
    # A chamber soak logged in °F: 68 ... 140 °F is 20 ... 60 °C, passed as °C it never falls below 50.
    log.write_text("t,temp,rate\n" + "".join(f"{k},{68 + k},{0.01 * k}\n" for k in range(73)))
    kwargs = dict(time="t:s", temp=["temp"], rate="rate:dph")
    with pytest.warns(UserWarning) as caught:
        rlgtherm.import_columns(log, **kwargs)
    messages = [str(w.message) for w in caught]
    assert len(messages) == 1 and "is the log in °F? That is 20.0 ... 60.0 °C" in messages[0], messages
    _, stderr = cli("import", "columns", log, "--time", "t:s", "--temp", "temp", "--rate", "rate:dph", "-o",
                    tmp_path / "cli.csv")
    assert f"rlgtherm: warning: {messages[0]}" in stderr
