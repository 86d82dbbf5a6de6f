#!/usr/bin/env bash
# baseline.sh RLGTHERM SOURCE_DIR TMPDIR: validate --baseline OLD.json (validation/baseline.h).
# On copies of paper-fixed.toml, of its gyro and of tests/data/population's small population:
#  - a suite's --json as the baseline of itself: exit 0, no regression; with another seed (fresh
#    noise) too;
#  - the same suite on a noisier gyro (ARW 0.001 -> 0.0015 °/sqrt(h): the 1 s stability after
#    +50 %, ~33 sigma of the difference's sampling error): exit 4, both runs' 1 s stabilities
#    named REGRESSED with old,
#    new and the noise; --json's baseline.passed false; a JUnit failure "baseline stability_after_dph";
#  - a run of the baseline no longer compensated: exit 4, named;
#  - a population against itself: no regression; on the noisier gyro: the stabilities' medians
#    named REGRESSED (intervals apart);
#  - a baseline of the other kind, or not JSON: exit 2 naming the file.
set -u
rlg=$1; src=$2; dir=$3
rm -rf "$dir"; mkdir -p "$dir/clean" "$dir/noisy"
fail=0
for kind in clean noisy; do
  arw=0.001; [ $kind = noisy ] && arw=0.0015
  sed "s/^arw_deg_per_sqrt_h = 0.001 /arw_deg_per_sqrt_h = $arw /" "$src/scenarios/gyros/default.toml" > "$dir/$kind/gyro.toml"
  grep -q "^arw_deg_per_sqrt_h = $arw " "$dir/$kind/gyro.toml" || { echo "could not set the ARW"; exit 1; }
  sed 's#^gyro = .*#gyro = "gyro.toml"#' "$src/scenarios/paper-fixed.toml" > "$dir/$kind/paper-fixed.toml"
  sed 's#^gyro = .*#gyro = "gyro.toml"#' "$src/tests/data/population/short-fixed.toml" > "$dir/$kind/short-fixed.toml"
  sed 's#^scenarios = .*#scenarios = ["paper-fixed.toml"]#' "$src/tests/cli/data/tiny_stability_bounds.toml" |
    sed '/^\[checks\]/,$d' > "$dir/$kind/suite.toml"
  cp "$src/tests/data/population/small.toml" "$dir/$kind/population.toml"
done
sed 's/^compensate = \["fixed+0", "fixed+60"\]/compensate = ["fixed+0"]/' "$dir/clean/suite.toml" > "$dir/clean/fewer.toml"

expect() {  # expect STATUS REGEX ARGS...: exit status STATUS and stdout matching REGEX
  local want=$1 regex=$2; shift 2
  out=$("$rlg" "$@" 2>"$dir/err"); got=$?
  if [ "$got" -ne "$want" ]; then echo "exit $got, expected $want: $*"; cat "$dir/err"; fail=1; fi
  if ! echo "$out" | grep -Eq -- "$regex"; then echo "no /$regex/ in the output of: $*"; echo "$out" | tail -8; fail=1; fi
}

"$rlg" validate "$dir/clean/suite.toml" --json > "$dir/base.json" || { echo "the clean suite fails"; fail=1; }
expect 0 "^baseline: no regression$" validate "$dir/clean/suite.toml" --baseline "$dir/base.json"
# Seed 3: fresh noise on which the suite's own checks pass too (exit 0 needs both).
expect 0 "10 metrics compared, .* 0 regressed" validate "$dir/clean/suite.toml" --baseline "$dir/base.json" --seed 3
expect 4 "REGRESSED stability_after_dph fixed\+0 \[eq2\]: 0\.06[0-9]* -> 0\.0[89][0-9]* °/h, \+0\.0[0-9]+ \(\+[0-9]+ %\), beyond the noise" \
  validate "$dir/noisy/suite.toml" --baseline "$dir/base.json"
expect 4 "REGRESSED stability_after_dph fixed\+60 \[eq2\]" validate "$dir/noisy/suite.toml" --baseline "$dir/base.json"
expect 4 "\"passed\": false" validate "$dir/noisy/suite.toml" --baseline "$dir/base.json" --json
"$rlg" validate "$dir/noisy/suite.toml" --baseline "$dir/base.json" --junit "$dir/noisy.xml" > /dev/null
grep -Eq 'name="baseline stability_after_dph fixed\+0">' "$dir/noisy.xml" && grep -q '<failure message="against ' "$dir/noisy.xml" ||
  { echo "no JUnit failure for the regressed stability"; fail=1; }
expect 4 "REGRESSED compensated fixed\+60 \[eq2\]: compensated and checked in the baseline, not any more" \
  validate "$dir/clean/fewer.toml" --baseline "$dir/base.json"

# Populations (small.toml fails a check of its own, exit 4 either way: the baseline's verdict is read).
"$rlg" validate "$dir/clean/population.toml" --json > "$dir/pop.json"
expect 4 "^baseline: no regression$" validate "$dir/clean/population.toml" --baseline "$dir/pop.json"
expect 4 "REGRESSED median stability_after_dph fixed-20 \[eq2\]: .*the new one lies wholly above the old one" \
  validate "$dir/noisy/population.toml" --baseline "$dir/pop.json"
expect 4 "note: p95 .*: not compared: its 95 % interval is unbounded for this many gyros" \
  validate "$dir/clean/population.toml" --baseline "$dir/pop.json"

# Refusals: exit 2, naming the file, before any work.
"$rlg" validate "$dir/clean/suite.toml" --baseline "$dir/pop.json" > /dev/null 2> "$dir/err"
[ $? -eq 2 ] && grep -q "pop.json: --baseline: a report of a population suite, this suite is a one-gyro suite" "$dir/err" ||
  { echo "a population baseline for a one-gyro suite:"; cat "$dir/err"; fail=1; }
echo "not json" > "$dir/bad.json"
"$rlg" validate "$dir/clean/suite.toml" --baseline "$dir/bad.json" > /dev/null 2> "$dir/err"
[ $? -eq 2 ] && grep -q "bad.json: --baseline: not JSON" "$dir/err" || { echo "a baseline that is not JSON:"; cat "$dir/err"; fail=1; }
[ $fail -eq 0 ] && echo "baseline: passes against itself and another seed, fails on a noisier gyro and a lost run"
exit $fail
