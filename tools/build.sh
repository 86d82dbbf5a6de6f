#!/usr/bin/env bash
# Set-up (Debian packages, if missing) and an incremental Release build into build/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
if [ ! -f build/CMakeCache.txt ]; then
  cmake -S . -B build -DCMAKE_BUILD_TYPE=Release >/dev/null
fi
cmake --build build -j2 >/dev/null
