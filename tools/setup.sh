#!/usr/bin/env bash
# Installs rlgtherm's build dependencies from Debian 12 packages (with --cross also the Cortex-M
# cross compiler). Idempotent: quiet and quick when everything is already there. Needs root (or
# sudo) only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake
  libeigen3-dev          # Eigen 3.4: dense linear algebra
  libsundials-dev        # SUNDIALS 6.4: CVODES stiff integrator
  libgtest-dev libgmock-dev googletest  # GoogleTest
  libbenchmark-dev       # Google Benchmark
  libcli11-dev           # CLI11: command-line parsing
  libtomlplusplus-dev    # toml++: scenario and gyro files
  nlohmann-json3-dev     # JSON outputs
  libfmt-dev             # formatting
  libtbb-dev             # oneTBB: population suites on every core (validation/population_suite.h)
  libboost-dev           # Boost.Random: the ziggurat tables of the noise's normal draws (sim/noise.h)
  libpcg-cpp-dev         # PCG random engines (pcg64_fast) under the noise's normal draws (sim/noise.h)
  zlib1g-dev             # crc32 for the .npz writer (io/npz.h)
  libceres-dev           # Ceres: nonlinear least squares (calibration)
  ccache                 # keeps compiled objects between builds (set up in CMakeLists.txt)
  pkg-config             # finds PLplot (its CMake package config needs every language binding)
  python3                # tools/readme_numbers.py: the README's numbers from the commands (a test checks them)
  libplplot-dev plplot-driver-cairo fonts-dejavu-core  # PLplot: diagnose --report PNG figures
  clang-14 libclang-rt-14-dev  # sanitizer and fuzzing job (tools/sanitize.sh): ASan, UBSan, libFuzzer
  time                   # /usr/bin/time: the CPU time of each CI step (.ci/run)
  valgrind               # memcheck of a short diagnose (ctest -L memcheck, .ci/run)
  python3-numpy          # tests/reference/refgen.py: arrays and the seeded PCG64 generator
  python3-scipy          # tests/reference/refgen.py: matrix exponential, Radau, root finding
  python3-pytest         # tests/reference: the generator's self-tests (ctest -L reference)
  pybind11-dev python3-pybind11 python3-dev  # the Python module rlgtherm (python/, docs/python.md); its tests use numpy and pytest
  python3-venv python3-setuptools python3-wheel  # pip install of the package into a venv (pyproject.toml, tools/wheel_test.sh)
  python3-dask python3-distributed  # rlgtherm_dask: population suites over Dask workers (docs/python.md, "Populations"); its test starts a local cluster
  python3-pandas python3-matplotlib  # the module's notebook helpers (Run.to_pandas, Trace.from_pandas, rlgtherm.plot), optional at import; their tests
)

# --cross: also the Cortex-M toolchain of the export tests' label cross (tests/export/cross.sh,
# docs/firmware.md), which CI runs.
if [ "${1:-}" = "--cross" ]; then
  packages+=(gcc-arm-none-eabi libnewlib-arm-none-eabi)
fi

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0

sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
echo "setup: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
$sudo apt-get update -qq >/dev/null
$sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
