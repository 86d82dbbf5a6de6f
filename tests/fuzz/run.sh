#!/usr/bin/env bash
# run.sh FUZZER SECONDS SEED_CORPUS WORK_DIR DICT [libFuzzer options...]
# Runs a libFuzzer harness for SECONDS from the seed corpus in the repo with a fixed seed. New
# inputs go to WORK_DIR/corpus (the repo's corpus is only read), a crash to WORK_DIR/crash-*;
# the exit status is libFuzzer's: 0 when no property failed and no sanitizer fired.
set -euo pipefail
fuzzer=$1; seconds=$2; seeds=$3; work=$4; dict=$5; shift 5
mkdir -p "$work/corpus"
# ASan's detection of a stack use after return (tools/sanitize/defaults.cpp turns it on) gives
# every call a frame on its fake stack: 13 times the cost of a JSON parse (fuzz_coefficients
# 800 inputs/s with it, 10,900 without; the others 2-3 times). The fuzzers run without it, for
# ten times the inputs; the sanitizer build's unit and CLI tests keep it. Other options stay.
export ASAN_OPTIONS="detect_stack_use_after_return=0${ASAN_OPTIONS:+:$ASAN_OPTIONS}"
# -timeout: an input taking 10 s is a hang worth a report (the slowest seed takes ~10 ms);
# -rss_limit_mb: 2 GB, beyond any legal input's need (the loaders cap a run's samples).
exec "$fuzzer" -seed=1 -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -dict="$dict" \
  -artifact_prefix="$work/" -print_final_stats=1 "$@" "$work/corpus" "$seeds"
