#!/usr/bin/env bash
# c_code.sh RLGTHERM CHECK_EXPORT WORKDIR COEFFS DATA PRECISION PREFIX MAX_DIFF MAX_TABLE2 FLAG_MARGIN
# Exports COEFFS as C (PRECISION double or float, names PREFIX_*), compiles the two files with
# gcc and clang-14 under -std=c99 -Wall -Wextra -Werror -pedantic and stricter warnings (and the
# header as C++), builds harness.c against them, feeds it every row of DATA and compares its
# output with the library's values, flags and Table 2 and with `rlgtherm compensate -o`
# (check_export; FLAG_MARGIN as it takes it).
set -euo pipefail
bin=$1; check=$2; work=$3; coeffs=$4; data=$5; precision=$6; prefix=$7; max_diff=$8; max_table2=$9; flag_margin=${10}
here=$(cd "$(dirname "$0")" && pwd)
rm -rf "$work"; mkdir -p "$work"
"$bin" export "$coeffs" --c "$work/code" --"$precision" --prefix "$prefix"
# The required flags, then warnings a firmware build commonly adds: a float build must not
# promote to double (-Wdouble-promotion), and no implicit conversion may lose a value.
flags=(-std=c99 -Wall -Wextra -Werror -pedantic -Wconversion -Wdouble-promotion -Wshadow -Wstrict-prototypes
       -Wmissing-prototypes -Wcast-qual -Wfloat-conversion -Wundef)
for cc in gcc clang-14; do
  "$cc" "${flags[@]}" -O2 -c "$work/code/$prefix.c" -o "$work/$prefix.$cc.o"
done
g++ -std=c++17 -Wall -Wextra -Werror -pedantic -fsyntax-only -x c++ "$work/code/$prefix.h"
upper=$(echo "$prefix" | tr '[:lower:]' '[:upper:]')
gcc "${flags[@]}" -Wno-missing-prototypes -O2 -DPREFIX="$prefix" -DPREFIX_UPPER="$upper" -DHEADER="\"$prefix.h\"" \
    -I"$work/code" "$here/harness.c" "$work/code/$prefix.c" -lm -o "$work/harness"
"$work/harness" "$data" > "$work/values.txt"
"$bin" compensate "$data" --coeffs "$coeffs" -o "$work/compensated.csv" 2> /dev/null
"$check" "$coeffs" "$data" "$work/values.txt" "$max_diff" "$max_table2" "$flag_margin" "$work/compensated.csv"
