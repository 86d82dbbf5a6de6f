#!/usr/bin/env bash
# alternate.sh FILTER ROUNDS BENCH_BINARY... : the least CPU time of each benchmark matching
# FILTER, per binary, over ROUNDS rounds that run the binaries in turn, five repetitions each.
#
# On a shared or virtual machine a median moves by tens of percent between minutes, as other
# work takes the core; the least of many runs is what the code costs when nothing else does,
# and taking the binaries in turn gives each the same minutes. Compare two builds of one
# benchmark executable (copy each build's binary aside first), or read one build's costs:
#
#   bash tools/bench/alternate.sh 'SimulateDefaultGyro(Reuse)?/24$' 4 /tmp/before/rlg_bench build/bin/rlg_bench
#
# Prints "binary benchmark least-CPU-ms", one line each: CPU time, the benchmark's own thread's
# (a benchmark that runs other threads, such as BM_PopulationPaperProtocol/2, reports real time
# in its counters; read those from its own output).
set -euo pipefail
if [ $# -lt 3 ]; then
  echo "usage: $0 FILTER ROUNDS BENCH_BINARY..." >&2
  exit 2
fi
filter=$1
rounds=$2
shift 2
for _ in $(seq "$rounds"); do
  for bin in "$@"; do
    # Google Benchmark's CSV: a header row, then name, iterations, real_time, cpu_time,
    # time_unit (unquoted), ..., error_occurred; aggregates and failed runs are left out.
    "$bin" --benchmark_filter="$filter" --benchmark_repetitions=5 --benchmark_format=csv 2>/dev/null |
      awk -F, -v bin="$bin" '
        NR == 1 { for (i = 1; i <= NF; ++i) if ($i == "error_occurred") err = i; next }
        $1 ~ /_(mean|median|stddev|cv)"$/ || (err && $err == "true") || $4 == "" { next }
        { t = $4; if ($5 == "us") t /= 1e3; else if ($5 == "ns") t /= 1e6; else if ($5 == "s") t *= 1e3
          print bin, $1, t }'
  done
done | awk '{ key = $1 " " $2; if (!(key in least) || $3 < least[key]) least[key] = $3 }
            END { for (key in least) printf "%s %.4g ms\n", key, least[key] }' | sort -k2,2 -k1,1
