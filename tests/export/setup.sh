#!/usr/bin/env bash
# setup.sh RLGTHERM SOURCE_DIR OUT_DIR: the data and coefficient files the export tests compile
# code for, in OUT_DIR:
#   fixed.csv, eq2.json         the paper suite (scenarios/paper-fixed.toml) and Eq. (2) fitted on
#                               its nine training runs fixed-30 ... fixed+50
#   poly_power_on.json          a cubic in T1 referred to power-on with rate and lag terms and
#                               a gradient to T2, on the same runs
#   imu.csv, px4.json           the IMU log's x axis (data/imu-thermal-cycle) and PX4's cubic
#   poly_terms.json             a cubic with hysteresis, rate and lag on the same log
#   ramps.csv                   the varying ambients (scenarios/ramps.toml): ramps to 60 °C and
#                               back, beyond the fixed runs' T1 range and far beyond their
#                               gradients and rates
#   products_hold.json          a quadratic in T1 with the products T1*(T2-T1), (T2-T1)^2,
#                               rate(T2-T1), T1*rate(T1) on the nine fixed runs, held at the
#                               fitted ranges (beyond_range hold, fitted offset)
#   products_extrapolate.json   the same products and a rate term, referred to power-on,
#                               extrapolating beyond the fitted ranges
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
"$bin" simulate "$src/scenarios/ramps.toml" -o "$out/ramps.csv"
products=('T1*(T2-T1)' '(T2-T1)^2' 'rate(T2-T1)' 'T1*rate(T1)')
"$bin" fit "$out/fixed.csv" --runs "$runs" --model poly --order 2 --terms "${products[@]}" --beyond-range hold \
  -o "$out/products_hold.json"
"$bin" fit "$out/fixed.csv" --runs "$runs" --model poly --order 2 --offset power_on --terms rate "${products[@]}" \
  --beyond-range extrapolate -o "$out/products_extrapolate.json"
