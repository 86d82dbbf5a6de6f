#!/usr/bin/env bash
# ramp_regression.sh RLGTHERM SCENARIOS_DIR TMPDIR: a regression on the ramps is caught.
# The bundled paper-suite.toml passes on its own gyro; on the same scenarios with a rate effect
# of 0.3 °/h per °C/min added to the gyro (bias.temperature_rate on T1, appended to each scenario
# as [[effects]]), its ramp limits fail: validate exits 4, and rise-fall fails its bias, its
# 100 s stability and its peak of 100 s means (the three limits of the ramps' table).
set -u
rlg=$1; src=$2; dir=$3
rm -rf "$dir"; mkdir -p "$dir"
for f in paper-fixed ramps varying-train; do
  sed "s#^gyro = \"gyros/#gyro = \"$src/gyros/#" "$src/$f.toml" > "$dir/$f.toml"
  printf '\n[[effects]]\nname = "bias.temperature_rate"\ntarget = "T1"\nk_dph_per_C_per_min = 0.3\n' >> "$dir/$f.toml"
done
cp "$src/paper-suite.toml" "$dir/"
fail=0
"$rlg" validate "$src/paper-suite.toml" > "$dir/clean.txt" || { echo "the bundled suite fails on its own gyro"; fail=1; }
"$rlg" validate "$dir/paper-suite.toml" > "$dir/regressed.txt"
got=$?
grep -E "FAIL|checks," "$dir/regressed.txt"
[ "$got" -eq 4 ] || { echo "exit status $got with the rate effect, expected 4"; fail=1; }
for check in "bias after" "stability 100s" "peak 100s"; do
  grep -Eq "FAIL +$check +rise-fall " "$dir/regressed.txt" || { echo "no failed '$check' on rise-fall"; fail=1; }
done
# The fixed runs do not see the effect (no temperature rate after the warm-up's first minutes):
# only ramps fail.
if grep -E "FAIL" "$dir/regressed.txt" | grep -q "fixed"; then echo "a fixed run failed"; fail=1; fi
exit $fail
