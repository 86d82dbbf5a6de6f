"""One version (CMakeLists.txt `project(rlgtherm VERSION x.y.z)`, its one source): the CLI's
--version, rlgtherm.__version__, the wheel's metadata where the package was installed from one,
and CHANGELOG.md's top entry all say it."""
import importlib.metadata
import re
from pathlib import Path

import pytest

import rlgtherm
from conftest import SOURCE, cli


def project_version():
    return re.search(r"^project\(rlgtherm VERSION (\d+\.\d+\.\d+) ", (SOURCE / "CMakeLists.txt").read_text(),
                     flags=re.M).group(1)


def test_the_cli_the_module_and_the_changelog_say_the_projects_version():
    version = project_version()
    out, _ = cli("--version")
    assert out == f"rlgtherm {version}\n"
    assert rlgtherm.__version__ == version
    top = re.search(r"^## (.*)$", (SOURCE / "CHANGELOG.md").read_text(), flags=re.M).group(1)
    assert top in (version, f"{version} (unreleased)"), f"CHANGELOG.md's top entry '{top}', the version {version}"


def test_an_installed_wheel_says_the_projects_version():
    try:
        dist = importlib.metadata.distribution("rlgtherm")
    except importlib.metadata.PackageNotFoundError:
        dist = None
    # Only the metadata of the package under test (a wheel in a venv, tools/wheel_test.sh), not
    # that of another copy elsewhere on the path; build/python has none.
    if dist is None or Path(dist.locate_file("rlgtherm/__init__.py")) != Path(rlgtherm.__file__):
        pytest.skip("rlgtherm not installed from a wheel (build/python)")
    assert dist.version == project_version() == rlgtherm.__version__
