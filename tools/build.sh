#!/usr/bin/env bash
# Set-up (Debian packages, if missing) and an incremental Release build into build/, with its
# progress every 10 %. ccache, when installed (tools/setup.sh installs it), keeps compiled
# objects in its cache directory ($CCACHE_DIR, default ~/.cache/ccache) for the next build of
# any clone on this machine: the first build takes 10-25 min on 2 cores, a rebuild of the same
# sources about 2 min.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
launcher=()
if command -v ccache > /dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="$PWD"  # paths relative to the clone: another clone's objects are hits
  # pcg_extras.hpp (the PCG engines) names __DATE__ __TIME__ in a time-seeded helper rlgtherm
  # never calls (its seeds are given); without this every file that includes it would miss.
  export CCACHE_SLOPPINESS=time_macros
fi
if [ ! -f build/CMakeCache.txt ]; then
  echo "build: configuring build/ (Release)" >&2
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" > /dev/null
echo "build: compiling into build/ (the first build takes 10-25 min on 2 cores; progress every 10 %)" >&2
cmake --build build -j2 | awk '/^\[ *[0-9]+%\]/ { s = $0; sub(/^\[ */, "", s); p = int(s);
  if (p >= next_p) { printf "build: %d %%\n", p > "/dev/stderr"; next_p = p - p % 10 + 10 } }'
echo "build: done, build/bin/rlgtherm" >&2
