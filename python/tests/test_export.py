"""export_c: the C code of `rlgtherm export --c` from Python (docs/firmware.md)."""
import pytest

import rlgtherm
from conftest import cli, cli_error


def test_export_c_of_a_file_writes_the_bytes_the_cli_writes(warmups, tmp_path):
    coeffs = str(warmups[2])
    cli("export", coeffs, "--c", tmp_path / "cli", "--float", "--prefix", "gyro_x")
    paths = rlgtherm.export_c(coeffs, tmp_path / "py", precision="float", prefix="gyro_x")
    assert paths == [str(tmp_path / "py" / "gyro_x.h"), str(tmp_path / "py" / "gyro_x.c")]
    for name in ("gyro_x.h", "gyro_x.c"):
        assert (tmp_path / "py" / name).read_bytes() == (tmp_path / "cli" / name).read_bytes()


def test_export_c_of_a_fitted_dict_writes_the_default_api_in_double(warmup_data, tmp_path):
    coeffs = rlgtherm.fit(warmup_data, runs=["w-20", "w+0", "w+20", "w+40"], model="poly", terms=["lag"])
    rlgtherm.export_c(coeffs, tmp_path)
    header = (tmp_path / "rlg_comp.h").read_text()
    assert "double rlg_comp_update(rlg_comp_state *s, double t_s, const double *T_C, double bias_dph);" in header
    assert "#define RLG_COMP_CHANNELS 1" in header
    assert "expm1(" in (tmp_path / "rlg_comp.c").read_text()


def test_export_c_refuses_what_the_cli_refuses_and_writes_nothing(warmups, tmp_path):
    message = cli_error("export", warmups[2], "--c", tmp_path / "cli", "--prefix", "gyro-x", status=2)
    with pytest.raises(ValueError) as e:
        rlgtherm.export_c(str(warmups[2]), tmp_path / "py", prefix="gyro-x")
    assert str(e.value) == message
    with pytest.raises(ValueError, match="precision 'half'"):
        rlgtherm.export_c(str(warmups[2]), tmp_path / "py", precision="half")
    assert not (tmp_path / "py").exists() and not (tmp_path / "cli").exists()
