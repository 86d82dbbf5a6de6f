#!/usr/bin/env bash
# Set-up (Debian packages, if missing) and an incremental Release build into build/, with its
# progress every 10 %. ccache (tools/setup.sh installs it; CMakeLists.txt sets it up) keeps
# compiled objects in its cache directory ($CCACHE_DIR, default ~/.cache/ccache) for the next
# build of any clone on this machine: a build of the same sources in a fresh clone takes only the
# cache's hits (both times: docs/testing.md, "CI step times").
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
if [ ! -f build/CMakeCache.txt ]; then
  echo "build: configuring build/ (Release)" >&2
fi
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release > /dev/null
echo "build: compiling into build/ (without ccache's objects, many minutes on 2 cores; progress every 10 %)" >&2
cmake --build build -j2 | awk '/^\[ *[0-9]+%\]/ { s = $0; sub(/^\[ */, "", s); p = int(s);
  if (p >= next_p) { printf "build: %d %%\n", p > "/dev/stderr"; next_p = p - p % 10 + 10 } }'
echo "build: done, build/bin/rlgtherm" >&2
