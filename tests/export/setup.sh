#!/usr/bin/env bash
# setup.sh RLGTHERM SOURCE_DIR OUT_DIR: the data and coefficient files the export tests compile
# code for, in OUT_DIR:
#   fixed.csv, eq2.json         the paper suite (scenarios/paper-fixed.toml) and Eq. (2) fitted on
#                               its nine training runs fixed-30 ... fixed+50
#   poly_power_on.json          a cubic in T1 referred to power-on with rate and lag terms and
#                               a gradient to T2, on the same runs
#   imu.csv, px4.json           the IMU log's x axis (data/imu-thermal-cycle) and PX4's cubic
#   poly_terms.json             a cubic with hysteresis, rate and lag on the same log
set -euo pipefail
bin=$1; src=$2; out=$3
mkdir -p "$out"
runs=fixed-30,fixed-20,fixed-10,fixed+0,fixed+10,fixed+20,fixed+30,fixed+40,fixed+50
"$bin" simulate "$src/scenarios/paper-fixed.toml" -o "$out/fixed.csv"
"$bin" fit "$out/fixed.csv" --runs "$runs" -o "$out/eq2.json"
"$bin" fit "$out/fixed.csv" --runs "$runs" --model poly --offset power_on --terms rate,lag,gradient:T2 \
  -o "$out/poly_power_on.json"
"$bin" import columns "$src/data/imu-thermal-cycle/imu_raw_data.csv" --time timestamp:us --temp imu.temperature \
  --rate imu.gyro.x:dps -o "$out/imu.csv"
"$bin" fit "$out/imu.csv" --model px4 -o "$out/px4.json"
"$bin" fit "$out/imu.csv" --model poly --order 3 --terms hysteresis,rate,lag -o "$out/poly_terms.json"
