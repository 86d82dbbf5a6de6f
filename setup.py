"""The wheel of the Python package rlgtherm (pyproject.toml): the package's Python files
(python/rlgtherm: __init__.py, plot.py, the type stubs, py.typed), rlgtherm_dask, and the extension
rlgtherm._core built by CMake for the interpreter running this (sys.executable: a venv's, say).

CMake builds in build-wheel/ beside build/ (same depth below the clone, so ccache's paths relative
to the clone are the same and the objects of a Release build in build/ are cache hits:
CMakeLists.txt); setuptools' own files go in build-wheel/ too. RLG_WHEEL_BUILD_DIR chooses
another directory; CMAKE_BUILD_PARALLEL_LEVEL the compile jobs (default: one per core).
"""
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

try:
    import wheel  # noqa: F401  Debian 12's setuptools builds a wheel with it (bdist_wheel)
except ImportError:
    sys.exit("rlgtherm: this Python has no 'wheel' package, which setuptools needs to build the wheel. "
             "Without a package index, make the venv see Debian's packages (python3-wheel, numpy): "
             "python3 -m venv --system-site-packages VENV (docs/python.md, \"Install with pip\")")

ROOT = Path(__file__).resolve().parent
VERSION = re.search(r"^project\(rlgtherm VERSION (\d+\.\d+\.\d+) ", (ROOT / "CMakeLists.txt").read_text(),
                    flags=re.M).group(1)
BUILD = Path(os.environ.get("RLG_WHEEL_BUILD_DIR", ROOT / "build-wheel"))


class CMakeBuild(build_ext):
    """Configures and builds CMake's target rlgtherm_python, then copies the extension where
    setuptools puts the wheel's files."""

    def build_extension(self, ext):
        cmake = shutil.which("cmake") or "cmake"
        # No rule messages: the Makefiles' "Building CXX object" echo is a cmake process per object,
        # a third of the CPU of a build whose compiles are all cache hits.
        subprocess.run([cmake, "-S", str(ROOT), "-B", str(BUILD), "-DCMAKE_BUILD_TYPE=Release",
                        f"-DPython_EXECUTABLE={sys.executable}", "-DBUILD_TESTING=OFF", "-DCMAKE_RULE_MESSAGES=OFF"],
                       check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
        subprocess.run([cmake, "--build", str(BUILD), "--target", "rlgtherm_python", "-j", jobs], check=True)
        built = sorted((BUILD / "python" / "rlgtherm").glob("_core.*"))
        if len(built) != 1:
            raise RuntimeError(f"expected one extension in {BUILD / 'python' / 'rlgtherm'}, found {built}")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built[0], target)


BUILD.mkdir(parents=True, exist_ok=True)  # egg_info writes there
setup(
    version=VERSION,
    package_dir={"": "python"},
    packages=["rlgtherm"],
    package_data={"rlgtherm": ["py.typed", "__init__.pyi"]},
    py_modules=["rlgtherm_dask"],
    ext_modules=[Extension("rlgtherm._core", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": str(BUILD / "setuptools")}, "egg_info": {"egg_base": str(BUILD)}},
    zip_safe=False,
)
