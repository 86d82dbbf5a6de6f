#!/usr/bin/env bash
# tools/firmware/numbers.sh [BUILD_DIR]: the numbers of docs/firmware.md for the code `rlgtherm
# export --c` writes, on a Cortex-M4 with FPU (-mcpu=cortex-m4 -mthumb -mfloat-abi=hard
# -mfpu=fpv4-sp-d16 -O2, Debian's arm-none-eabi-gcc and newlib): for Eq. (2) on the paper suite
# and a cubic + hysteresis + rate + lag on the IMU log (the export tests' fixtures in
# BUILD_DIR/tests/export, default build), in double and float:
#   object   bytes of rlg_comp.o (text + data; arm-none-eabi-size)
#   linked   bytes the compensator adds to a program: libgcc's double routines, newlib's expm1 or
#            expm1f included (a bench program with and without it)
#   stack    rlg_comp_update's own frame (-fstack-usage), and the deepest stack below its entry
#            with every routine it calls, as qemu-arm executed it
#   instr    instructions per update executed under qemu-arm (user mode, one instruction per
#            block): in the B0 window and after it, each the difference of two runs over the
#            rows of one run divided by the rows between them. Instructions, not cycles: QEMU
#            models no timing (on a Cortex-M4 most take 1 cycle, loads 2, taken branches 2-4).
# Needs gcc-arm-none-eabi, libnewlib-arm-none-eabi and qemu-user (apt-get install); python3.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
build=$(cd "${1:-$here/../../build}" && pwd)
data=$build/tests/export
for tool in arm-none-eabi-gcc qemu-arm python3; do
  command -v $tool > /dev/null || { echo "numbers.sh: $tool not found (apt-get install gcc-arm-none-eabi libnewlib-arm-none-eabi qemu-user)"; exit 2; }
done
[ -f "$data/eq2.json" ] || { echo "numbers.sh: no $data/eq2.json: run ctest -R export.setup_coefficients in $build"; exit 2; }
work=$(mktemp -d); trap 'rm -rf "$work"' EXIT
target=(-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -O2)

# bench_data.h of `rows` rows of run `run` in `csv` from row `start`, the channels named, in `type`.
data_header() {
  python3 - "$@" <<'PY'
import csv, sys
path, run, chans, start, rows, real, out = sys.argv[1:8]
chans, start, rows = chans.split(","), int(start), int(rows)
lines = [l for l in open(path) if not l.startswith("#")]
sel = [r for r in csv.DictReader(lines) if r["run"] == run][start:start + rows]
f = "f" if real == "float" else ""
lit = lambda v: repr(float(v)) + f
with open(out, "w") as o:
    o.write(f"#define BENCH_ROWS {rows}\n")
    o.write(f"static const {real} bench_t[{rows}] = {{{','.join(lit(r['t_s']) for r in sel)}}};\n")
    o.write(f"static const {real} bench_b[{rows}] = {{{','.join(lit(r['bias_dph']) for r in sel)}}};\n")
    T = ",".join("{" + ",".join(lit(r[c]) for c in chans) + "}" for r in sel)
    o.write(f"static const {real} bench_T[{rows}][{len(chans)}] = {{{T}}};\n")
PY
}

# instructions N: instructions qemu-arm executes for bench.elf N.
instructions() {
  qemu-arm -cpu cortex-a15 -singlestep -d exec,nochain -D "$dir/exec.log" "$dir/bench.elf" "$1"
  grep -c '^Trace' "$dir/exec.log"
}

printf '%-32s %-6s %7s %7s %6s %6s %10s %10s\n' model type object linked frame stack "instr(B0)" "instr(after)"
for spec in "eq2:fixed.csv:fixed+20:T1,T2:Eq. (2), paper suite" \
            "poly_terms:imu.csv:imu_raw_data:T1:cubic+hyst+rate+lag, IMU log"; do
  IFS=: read -r model csv run chans label <<< "$spec"
  for precision in double float; do
    dir=$work/${model}_$precision; mkdir -p "$dir"
    "$build/bin/rlgtherm" export "$data/$model.json" --c "$dir" --"$precision" > /dev/null
    # The rows: the first 700 of the run (the IMU log's sample period is 0.5 s, so its B0 window
    # holds 238 rows; the paper suite's 1 s, 120 rows).
    data_header "$data/$csv" "$run" "$chans" 0 700 "$precision" "$dir/bench_data.h"
    cp "$here/bench.c" "$here/start.c" "$dir/"
    (cd "$dir" &&
     arm-none-eabi-gcc "${target[@]}" -std=c99 -fstack-usage -c rlg_comp.c -o rlg_comp.o &&
     arm-none-eabi-gcc "${target[@]}" -std=c99 -nostartfiles -static start.c bench.c rlg_comp.o -lm -lc -lgcc -o bench.elf &&
     arm-none-eabi-gcc "${target[@]}" -std=c99 -nostartfiles -static -DSTUB start.c bench.c -lm -lc -lgcc -o stub.elf)
    read -r text dat _ < <(arm-none-eabi-size "$dir/rlg_comp.o" | tail -1)
    read -r btext bdat _ < <(arm-none-eabi-size "$dir/bench.elf" | tail -1)
    read -r stext sdat _ < <(arm-none-eabi-size "$dir/stub.elf" | tail -1)
    frame=$(grep rlg_comp_update "$dir/rlg_comp.su" | cut -f2)
    # The deepest stack below rlg_comp_update's entry: SP at its first instruction minus the
    # lowest SP while it runs (registers logged at every instruction of the first 130 rows).
    entry=$(arm-none-eabi-nm "$dir/bench.elf" | awk '$3 == "rlg_comp_update" {print $1}')
    qemu-arm -cpu cortex-a15 -singlestep -d cpu,nochain -D "$dir/cpu.log" "$dir/bench.elf" 130
    stack=$(python3 - "$dir/cpu.log" "$entry" <<'PY'
import re, sys
entry = int(sys.argv[2], 16) & ~1
sp_entry, low = None, None
for m in re.finditer(r"R13=([0-9a-f]{8}) R14=[0-9a-f]{8} R15=([0-9a-f]{8})", open(sys.argv[1]).read()):
    sp, pc = int(m.group(1), 16), int(m.group(2), 16)
    if pc == entry and sp_entry is None:
        sp_entry = sp
    if sp_entry is not None:
        low = sp if low is None else min(low, sp)
print(sp_entry - low)
PY
)
    if [ "$model" = eq2 ]; then window=120; else window=238; fi
    i0=$(instructions 1); i1=$(instructions "$window"); i2=$(instructions 300); i3=$(instructions 700)
    printf '%-32s %-6s %7d %7d %6d %6d %10.0f %10.0f\n' "$label" "$precision" $((text + dat)) \
      $((btext + bdat - stext - sdat)) "$frame" "$stack" \
      "$(awk -v a="$i1" -v b="$i0" -v n="$window" 'BEGIN { print (a - b) / (n - 1) }')" \
      "$(awk -v a="$i3" -v b="$i2" 'BEGIN { print (a - b) / 400 }')"
  done
done
