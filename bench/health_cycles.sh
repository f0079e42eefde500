#!/usr/bin/env bash
# The health watch's instructions per sample on the board's ISA (aarch64, counted under qemu-user)
# and on the host (x86-64, callgrind) as a cross-check, and the share of the 8 kHz sample budget
# that makes on an assumed board core. Each count is the difference of two runs of count_health
# (MODE 1 steps the watch over one full cycle of bench_health's input, MODE 0 only prepares it),
# divided by the samples: start-up, input generation and the C library cancel out.
# Usage: bench/health_cycles.sh [HOST_BUILD] [AARCH64_BUILD]
#   HOST_BUILD/bench/count_health: cmake --build build --target count_health
#   AARCH64_BUILD/bench/count_health: cmake --preset cross-aarch64 -DFTSTACK_BUILD_BENCH=ON,
#   then cmake --build build-aarch64 --target count_health (sysroot: cmake/make-sysroot.sh arm64)
# The core: CORE_MHZ (default 1200, the Cortex-A53 of a Raspberry Pi 3, the slowest board the
# README names) at IPC_LOW … IPC_HIGH instructions per cycle (default 0.5 … 1.0: an in-order,
# dual-issue core on branchy integer code).
set -euo pipefail
HOST=${1:-build}
A64=${2:-build-aarch64}
CORE_MHZ=${CORE_MHZ:-1200}
IPC_LOW=${IPC_LOW:-0.5}
IPC_HIGH=${IPC_HIGH:-1.0}
HERE=$(cd "$(dirname "$0")" && pwd)
A64_LIB="$HERE/../out/sysroot-arm64/usr/lib/aarch64-linux-gnu"
RINGS=20

# Instructions of one aarch64 run: qemu's translation and execution trace, summed by the awk.
count_a64() {
  local out
  out=$(qemu-aarch64 -L /usr/aarch64-linux-gnu \
    -E "LD_LIBRARY_PATH=/usr/aarch64-linux-gnu/lib:$A64_LIB" -d in_asm,exec,nochain -D /dev/fd/3 \
    "$A64/bench/count_health" "$@" 3>&1 >/dev/null | awk -f "$HERE/aarch64_insn_count.awk")
  set -- $out
  [ "$2" = 0 ] || echo "  (warning: $2 executed blocks without a translation in the trace)" >&2
  echo "$1"
}
# Instructions of one host run (callgrind's Ir total).
count_host() {
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$HOST/bench/count_health" "$@" 2>&1 \
    >/dev/null | awk '/Collected :/ { print $4 }'
}
# per COUNTER RATE SAMPLES MODE: instructions per sample (or per analysis) of MODE over MODE 0.
per() {
  local a b
  a=$("$1" "$2" "$3" "$4")
  b=$("$1" "$2" "$3" 0)
  awk -v a="$a" -v b="$b" -v n="$3" 'BEGIN { printf "%.0f", (a - b) / n }'
}
# share INSN RATE: the cycle range and the share of one sample period on the assumed core.
share() {
  awk -v i="$1" -v r="$2" -v mhz="$CORE_MHZ" -v lo="$IPC_LOW" -v hi="$IPC_HIGH" 'BEGIN {
    budget = mhz * 1e6 / r
    printf "%.0f … %.0f cycles = %.2f … %.2f %% of the %.0f-cycle budget at %d Hz", i / hi, i / lo,
      100 * i / hi / budget, 100 * i / lo / budget, budget, r }'
}

report() {
  local name=$1 counter=$2
  printf '\n== health watch, %s ==\n' "$name"
  for rate in 1000 8000; do
    local n=$((4 * rate))  # one full cycle of the input: steps, ringing, holds, zero spells
    local i
    i=$(per "$counter" "$rate" "$n" 1)
    printf '  %d Hz: %s instructions per sample (mean over %d samples)\n' "$rate" "$i" "$n"
    [ "$counter" = count_a64 ] && printf '         %s\n' "$(share "$i" "$rate")"
  done
  local r w
  w=$(per "$counter" 1000 "$RINGS" 2)
  printf '  worst sample: + %s instructions (a ringing analysis'"'"'s level and first crossing slice, an upper bound)\n' "$w"
  [ "$counter" = count_a64 ] && printf '         %s\n' "$(share "$w" 8000)"
  r=$(per "$counter" 1000 "$RINGS" 3)
  printf '  one whole ringing analysis (512 samples, spread over 4 samples): %s instructions\n' "$r"
  return 0
}

echo "assumed board core: ${CORE_MHZ} MHz at ${IPC_LOW} … ${IPC_HIGH} instructions per cycle"
if [ -x "$A64/bench/count_health" ] && command -v qemu-aarch64 >/dev/null 2>&1; then
  report "aarch64 (qemu-aarch64 trace of $A64/bench/count_health)" count_a64
else
  printf '\n== aarch64: skipped (no %s/bench/count_health or no qemu-aarch64) ==\n' "$A64"
fi
if [ -x "$HOST/bench/count_health" ] && command -v valgrind >/dev/null 2>&1; then
  report "host x86-64 (callgrind of $HOST/bench/count_health), cross-check" count_host
else
  printf '\n== host: skipped (no %s/bench/count_health or no valgrind) ==\n' "$HOST"
fi
