#!/usr/bin/env bash
# make_plot_data.sh RLGTHERM FIXED_CSV COEFFS TWO_RUNS_CSV COMPENSATED_CSV: the data of the --plot
# tests (fixture plot_data). Two runs keep each verb's figures to seconds:
#   TWO_RUNS_CSV     runs fixed+0 and fixed+60 of FIXED_CSV (make_run_subset.sh);
#   COMPENSATED_CSV  the same compensated with COEFFS (`compensate -o`), for evaluate --plot.
set -eu
bin=$1; fixed=$2; coeffs=$3; two_runs=$4; compensated=$5
"$(dirname "$0")/make_run_subset.sh" "$fixed" "$two_runs" fixed+0 fixed+60
"$bin" compensate "$two_runs" --coeffs "$coeffs" -o "$compensated" > /dev/null
