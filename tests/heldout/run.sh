#!/usr/bin/env bash
# run.sh PYTHON RLGTHERM WORKDIR PERIOD: gen.py's 34 cases at PERIOD s samples into WORKDIR (made
# afresh), then score.py --check on them: `rlgtherm diagnose` blind on each, named or a twin at
# its size on 22 of the 24 effect cases and no alarm on the 10 nulls (README.md). RLG_HELDOUT_JOBS
# processes at once (2).
set -euo pipefail
py=$1; rlg=$2; work=$3; period=$4
here=$(cd "$(dirname "$0")" && pwd)
jobs=${RLG_HELDOUT_JOBS:-2}
rm -rf "$work"
"$py" "$here/gen.py" --out "$work" --sample-period "$period" --jobs "$jobs" >/dev/null
"$py" "$here/score.py" --rlgtherm "$rlg" --cases "$work" --jobs "$jobs" --check
