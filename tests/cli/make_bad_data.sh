#!/usr/bin/env bash
# make_bad_data.sh RLGTHERM DATA_DIR ONE_AMBIENT_CSV SHORT_RUN_CSV: simulates the data of the
# refusals that need well-formed files the commands still cannot use (fixture bad_data):
#   ONE_AMBIENT_CSV  DATA_DIR/one_ambient.toml, three runs at one ambient temperature: Eq. (2)'s
#                    start-temperature terms cannot be separated (fit exits 3);
#   SHORT_RUN_CSV    DATA_DIR/short_run.toml, a 60 s run, shorter than the 120 s B0 window
#                    (fit, compensate and diagnose exit 2).
set -eu
bin=$1; data=$2; one_ambient=$3; short_run=$4
"$bin" simulate "$data/one_ambient.toml" -o "$one_ambient"
"$bin" simulate "$data/short_run.toml" -o "$short_run"
