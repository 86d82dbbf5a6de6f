#!/usr/bin/env bash
# stream_equals_batch.sh RLGTHERM DATA.csv COEFFS.json: compensate in batch (-o) and in
# streaming mode (stdin -> stdout) must write the same bytes.
set -eu
bin=$1; data=$2; coeffs=$3; d=$(mktemp -d); trap 'rm -rf "$d"' EXIT
"$bin" compensate "$data" --coeffs "$coeffs" -o "$d/batch.csv" > /dev/null
"$bin" compensate - --stream --coeffs "$coeffs" < "$data" > "$d/stream.csv"
cmp "$d/batch.csv" "$d/stream.csv"
echo "batch and streaming outputs identical ($(wc -l < "$d/batch.csv") lines)"
