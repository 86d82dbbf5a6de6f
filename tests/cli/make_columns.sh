#!/usr/bin/env bash
# make_columns.sh IN_CSV OUT_CSV FIELDS: the rows of IN_CSV (comment lines dropped) with only the
# comma-separated fields FIELDS (cut -f syntax, e.g. 1,2,4), for refusals of data that lack a
# column (e.g. the IMU log without its temperature: fixture imu_no_temperature).
set -euo pipefail
grep -v '^#' "$1" | cut -d, -f"$3" > "$2"
