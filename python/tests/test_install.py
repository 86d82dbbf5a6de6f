"""The documented install rule (docs/python.md): `cmake --install build --component python`
puts the package (the extension, its stubs and py.typed) and its Dask helper (rlgtherm_dask) in a directory on Debian's /usr/bin/python3
search path, and they import from there. Installed under a temporary DESTDIR, so the machine is left as it was."""
import os
import subprocess

import pytest

BUILD = os.environ.get("RLG_BUILD_DIR")


@pytest.mark.skipif(not BUILD, reason="needs RLG_BUILD_DIR (set by ctest)")
def test_cmake_install_puts_the_module_where_debian_python_finds_it(tmp_path):
    cmake = os.environ.get("RLG_CMAKE", "cmake")
    subprocess.run([cmake, "--install", BUILD, "--component", "python"], check=True, capture_output=True,
                   env={**os.environ, "DESTDIR": str(tmp_path)})
    installed = list(tmp_path.rglob("_core*.so"))
    assert len(installed) == 1, installed
    package = installed[0].parent
    assert package.name == "rlgtherm"
    assert {"__init__.py", "__init__.pyi", "py.typed", "plot.py"} <= {p.name for p in package.iterdir()}  # typed (PEP 561)
    directory = "/" + str(package.parent.relative_to(tmp_path))
    clean = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    search_path = subprocess.run(["/usr/bin/python3", "-c", "import sys; print('\\n'.join(sys.path))"],
                                 capture_output=True, text=True, check=True, env=clean).stdout.splitlines()
    assert directory in search_path
    where = subprocess.run(["/usr/bin/python3", "-c", "import rlgtherm, rlgtherm_dask\n"
                            "print(rlgtherm.__file__); print(rlgtherm_dask.__file__)"],
                           capture_output=True, text=True, check=True, cwd=tmp_path,  # not the build's copies
                           env={**clean, "PYTHONPATH": str(package.parent)}).stdout.split()
    assert where == [str(package / "__init__.py"), str(package.parent / "rlgtherm_dask.py")]  # the helper beside it
