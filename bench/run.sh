#!/usr/bin/env bash
# Runs the benchmarks briefly and prints the figures the issues ask for. Usage: bench/run.sh [BUILD_DIR]
set -euo pipefail
BUILD=${1:-build}
B="$BUILD/bench"
MIN_TIME=${BENCH_MIN_TIME:-0.2}

section() { printf '\n== %s ==\n' "$*"; }

# --- firmware core (issue 2): ns per sample, fixed point vs double-precision Eigen, same run ----
if [ -x "$B/bench_core" ]; then
  section "fixed-point core vs double-precision Eigen (ns per sample, one run)"
  "$B/bench_core" --benchmark_min_time="$MIN_TIME" --benchmark_format=csv 2>/dev/null |
    awk -F, 'NR>1 && $1 ~ /BM_/ { gsub(/"/,"",$1); t[$1]=$3; printf "  %-24s %8.1f ns\n", $1, $3 }
      END {
        for (n = 6; n <= 8; n += 2) {
          f = t["BM_FixedMatrix/" n]; e = t["BM_EigenDouble/" n]; c = t["BM_FixedCore/" n "/1"];
          if (f > 0 && e > 0) printf "  N=%d: matrix step fixed/double = %.2f; whole core (filter 1) %.1f ns\n", n, f / e, c
        }
      }'
fi
