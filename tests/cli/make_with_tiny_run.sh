#!/usr/bin/env bash
# make_with_tiny_run.sh FIXED_CSV TWO_ROW_RUN_CSV OUT_CSV: writes OUT_CSV, the runs of FIXED_CSV
# (its comment lines dropped) followed by a run 'tiny': the two data rows of TWO_ROW_RUN_CSV
# (run 'a' there). A run too short for the Eq. (2) fit among good ones: the release build once
# exited 0 with coefficients read past it (fixture tiny_run_data).
set -eu
fixed=$1; two_rows=$2; out=$3
grep -v '^#' "$fixed" > "$out"
tail -n 2 "$two_rows" | sed 's/^a,/tiny,/' >> "$out"
