#!/usr/bin/env bash
# make_no_t4.sh FIXED_CSV NO_T4_CSV ONLY_T1_CSV: the runs of FIXED_CSV (columns run, t_s, T_amb,
# T1, T2, T3, T4, bias_dph; comment lines dropped) with fewer temperature channels, for pairs'
# refusals and its --all (fixture no_t4_data):
#   NO_T4_CSV    without T4: the paper's combinations M2, M3, M5, M6 cannot be formed;
#   ONLY_T1_CSV  T1 alone: no pair of channels at all.
set -euo pipefail
fixed=$1; no_t4=$2; only_t1=$3
grep -v '^#' "$fixed" | cut -d, -f1-6,8 > "$no_t4"
grep -v '^#' "$fixed" | cut -d, -f1-4,8 > "$only_t1"
