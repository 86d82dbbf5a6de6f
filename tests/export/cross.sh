#!/usr/bin/env bash
# cross.sh RLGTHERM DATA_DIR WORKDIR: every exported model (eq2, px4, poly_terms, poly_power_on,
# products_hold, products_extrapolate in DATA_DIR, tests/export/setup.sh), in double and float,
# compiled for a Cortex-M4 with an FPU by Debian's arm-none-eabi-gcc under -std=c99 -Wall -Wextra
# -Werror -pedantic and stricter warnings; float code must call no double-precision routine (no
# __aeabi_d*, no expm1). Prints
# each object's size and the stack use of its update function. Exit 77 (skipped) without the
# compiler: bash tools/setup.sh --cross installs it.
set -euo pipefail
bin=$1; data=$2; work=$3
cc=arm-none-eabi-gcc
if ! command -v "$cc" > /dev/null; then
  echo "skipped: $cc not found (bash tools/setup.sh --cross installs gcc-arm-none-eabi and libnewlib-arm-none-eabi)"
  exit 77
fi
rm -rf "$work"; mkdir -p "$work"
target=(-mcpu=cortex-m4 -mthumb -mfloat-abi=hard -mfpu=fpv4-sp-d16 -O2)
flags=(-std=c99 -Wall -Wextra -Werror -pedantic -Wconversion -Wdouble-promotion -Wshadow -Wstrict-prototypes
       -Wmissing-prototypes -Wcast-qual -Wfloat-conversion -Wundef)
printf '%-20s %-7s %6s %6s %6s  %s\n' model type text data bss "stack of rlg_comp_update (bytes)"
for model in eq2 px4 poly_terms poly_power_on products_hold products_extrapolate; do
  for precision in double float; do
    dir=$work/${model}_$precision
    "$bin" export "$data/$model.json" --c "$dir" --"$precision" > /dev/null
    (cd "$dir" && "$cc" "${flags[@]}" "${target[@]}" -fstack-usage -c rlg_comp.c -o rlg_comp.o)
    if [ "$precision" = float ] && arm-none-eabi-nm -u "$dir/rlg_comp.o" | grep -E '__aeabi_d|\bexpm1$'; then
      echo "FAILED: the float code of $model calls the double-precision routines above"; exit 1
    fi
    read -r text dat bss _ < <(arm-none-eabi-size "$dir/rlg_comp.o" | tail -1)
    printf '%-20s %-7s %6s %6s %6s  %s\n' "$model" "$precision" "$text" "$dat" "$bss" \
      "$(grep rlg_comp_update "$dir/rlg_comp.su" | cut -f2-)"
  done
done
