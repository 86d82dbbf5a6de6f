#!/usr/bin/env bash
# The Python package as a user installs it (docs/python.md, "Install with pip"), run by CI
# (.ci/checks.mk, target wheel): the wheel built by pip from this clone (pyproject.toml, setup.py:
# CMake in build-wheel/, its objects ccache hits of the Release build's), installed into a fresh
# venv with Debian's packages visible (--system-site-packages: numpy, pytest, dask; no index),
# then the Python tests run against it from another directory with no PYTHONPATH, so that the
# installed copy is the one tested. Needs the Release build (build/bin/rlgtherm: the tests compare
# the module with the CLI). Prints the wheel's build time (the step's: docs/testing.md, "CI step times").
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
out=build/wheel
rm -rf "$out" build-wheel
mkdir -p "$out"
/usr/bin/python3 -m venv --system-site-packages "$out/venv"
python=$root/$out/venv/bin/python

# A venv that does not see Debian's packages has no `wheel` for setuptools: pip must stop at once
# with setup.py's message naming the fix, not setuptools' "invalid command 'bdist_wheel'".
/usr/bin/python3 -m venv "$out/plain"
if "$out/plain/bin/python" -m pip install --no-build-isolation --no-index . > "$out/plain.log" 2>&1; then
  echo "wheel: pip installed into a venv without Debian's packages; expected setup.py's refusal" >&2; exit 1
fi
grep -q -- "--system-site-packages" "$out/plain.log" || { cat "$out/plain.log" >&2; echo "wheel: no pointer to --system-site-packages" >&2; exit 1; }
echo "wheel: a venv without Debian's packages is refused, naming --system-site-packages"

t=$(date +%s)
"$python" -m pip wheel --no-build-isolation --no-index --no-deps --quiet -w "$out/dist" .
echo "wheel: built $(ls "$out"/dist) in $(( $(date +%s) - t )) s"
"$python" -m pip install --no-index --quiet "$out"/dist/rlgtherm-*.whl

cd "$(mktemp -d)"  # not the clone: its python/rlgtherm has no extension
unset PYTHONPATH
"$python" - "$root/$out/venv" <<'PY'
import pathlib, sys
import rlgtherm, rlgtherm_dask
venv = pathlib.Path(sys.argv[1])
for module in (rlgtherm, rlgtherm_dask):
    assert venv in pathlib.Path(module.__file__).parents, f"{module.__name__} imported from {module.__file__}, not {venv}"
assert (pathlib.Path(rlgtherm.__file__).parent / "py.typed").exists()
print(f"wheel: rlgtherm {rlgtherm.__version__} from {rlgtherm.__file__}")
PY
RLG_BIN=$root/build/bin/rlgtherm RLG_SOURCE_DIR=$root PYTHONDONTWRITEBYTECODE=1 \
  "$python" -m pytest -q -p no:cacheprovider "$root/python/tests"
