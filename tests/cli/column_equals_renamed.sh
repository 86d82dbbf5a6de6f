#!/usr/bin/env bash
# column_equals_renamed.sh RLGTHERM DATA.csv COEFFS.json: `compensate --column my_dph` on a copy
# of DATA whose bias_dph is renamed my_dph gives the bytes of plain `compensate` on DATA (up to
# the names), in batch, streaming and --json.
set -eu
bin=$1; data=$2; coeffs=$3; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
awk -F, 'BEGIN { OFS = "," } /^#/ { print; next } !h { for (i = 1; i <= NF; i++) if ($i == "bias_dph") $i = "my_dph"; h = 1 } { print }' \
  "$data" > "$d/renamed.csv"
"$bin" compensate "$data" --coeffs "$coeffs" -o "$d/a.csv" > /dev/null
"$bin" compensate "$d/renamed.csv" --coeffs "$coeffs" --column my_dph -o "$d/b.csv" > /dev/null
head -c 300 "$d/b.csv" | grep -q "my_dph,my_comp_dph" || { echo "no my_comp_dph column after my_dph"; exit 1; }
sed 's/my_comp_dph/bias_comp_dph/; s/my_dph/bias_dph/' "$d/b.csv" | cmp - "$d/a.csv"
"$bin" compensate - --stream --coeffs "$coeffs" --column my_dph < "$d/renamed.csv" |
  sed 's/my_comp_dph/bias_comp_dph/; s/my_dph/bias_dph/' | cmp - "$d/a.csv"
"$bin" compensate "$data" --coeffs "$coeffs" --json > "$d/a.json"
"$bin" compensate "$d/renamed.csv" --coeffs "$coeffs" --column my_dph --json | sed 's/"my_dph"/"bias_dph"/; s/"my_comp_dph"/"bias_comp_dph"/' | cmp - "$d/a.json"
echo "compensate --column my_dph equals compensate on bias_dph: batch, stream and json ($(wc -l < "$d/a.csv") lines)"
