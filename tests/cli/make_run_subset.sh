#!/usr/bin/env bash
# make_run_subset.sh CSV OUT_CSV RUN...: writes OUT_CSV, the header of the tidy CSV file CSV and
# the rows of the named runs, in CSV's order, without its comment lines: a test on one or two
# runs of a larger simulation.
set -eu
csv=$1; out=$2; shift 2
awk -F, -v runs="$*" '
  BEGIN { n = split(runs, r, " "); for (i = 1; i <= n; ++i) keep[r[i]] = 1 }
  /^#/ { next }
  $1 == "run" || ($1 in keep)' "$csv" > "$out"
