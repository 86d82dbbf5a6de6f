#!/usr/bin/env bash
# validate_unreadable.sh RLGTHERM DEFAULT_GYRO: a suite whose simulation leaves the plausible
# range (what `simulate` refuses to write) is refused, not evaluated: exit 2, the scenario's
# file, line and run and the value in the message, nothing on standard output, and the JUnit
# file one errored testcase. In a population, the message names the gyro whose draw left it.
set -eu
bin=$1; gyro=$2; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
cat > "$d/s.toml" <<'TOML'
gyro = "hot.toml"
seed = 1
[defaults]
duration_s = 3600
sample_period_s = 1
[[runs]]
id = "a"
ambient = { profile = "constant", value_C = 20 }
[[runs]]
id = "b"
ambient = { profile = "constant", value_C = 30 }
[[runs]]
id = "c"
ambient = { profile = "constant", value_C = 40 }
TOML
fit='[[fits]]
name = "f"
pair = ["T1", "T2"]
runs = ["a", "b", "c"]
compensate = ["a", "b", "c"]'
printf 'scenarios = ["s.toml"]\n%s\n' "$fit" > "$d/suite.toml"
# A discharge of 1e4 W for 0.6 (a mistyped power): T1 passes 150 °C within a minute. No check
# limits the bias, so an evaluation would pass every check it makes.
sed 's/^power_W = 0.6 /power_W = 1e4 /' "$gyro" > "$d/hot.toml"
grep -q '^power_W = 1e4 ' "$d/hot.toml"  # the case is what it says
# refused SUITE PATTERN [ARGS...]: validate exits 2 with a message matching PATTERN and writes
# nothing on standard output.
refused() {
  local suite=$1 pattern=$2 status=0; shift 2
  "$bin" validate "$suite" "$@" > "$d/out.txt" 2> "$d/err.txt" || status=$?
  [ "$status" -eq 2 ] || { echo "$suite: exit $status, expected 2"; cat "$d/err.txt"; exit 1; }
  grep -q "$pattern" "$d/err.txt" || { echo "$suite: unexpected message:"; cat "$d/err.txt"; exit 1; }
  [ ! -s "$d/out.txt" ] || { echo "$suite: partial output:"; cat "$d/out.txt"; exit 1; }
}
refused "$d/suite.toml" "s.toml:6: run 'a': the simulated column 'T1' = .*outside the plausible range -80...150 °C" \
  --junit "$d/j.xml"
grep -q '<error message=".*outside the plausible range' "$d/j.xml" || { echo "no errored testcase:"; cat "$d/j.xml"; exit 1; }
# 32 W: the nominal gyro (gyro 0) stays below 150 °C, gyro 12 of this draw (5 % spread on the
# power) passes it in the 40 °C run.
sed 's/^power_W = 0.6 /power_W = 32 /' "$gyro" > "$d/hot.toml"
printf 'scenarios = ["s.toml"]\nseed = 5\n%s\n[population]\ncount = 24\n[[population.spread]]\nparameter = "sources.*.power_W"\ndistribution = "lognormal"\nrelative_sigma = 0.05\n' "$fit" > "$d/pop.toml"
refused "$d/pop.toml" "pop.toml: gyro 12 (\`validate --gyro 12\`): .*s.toml:12: run 'c': the simulated column 'T2' = .*outside the plausible range"
echo "refused with file, line, run, value (and gyro 12 in the population); no output"
