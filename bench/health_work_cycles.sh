#!/usr/bin/env bash
# The health watch over whole work cycles: ftd runs one `work:NAME` profile (sim/work_cycles.hpp)
# for HOURS of simulated time at 1 kHz, unpaced (as fast as the machine allows: the watch's time
# base is the sample count, so it sees what a paced run shows), with any --sim-effect given.
# From the status lines (--print-hz: one every few simulated seconds) it takes every finding seen,
# when the first of each cause appeared (simulated s), the coverage at the end; from /proc the
# daemon's CPU (all threads, user + system, including the piecewise composition of the signal)
# and its peak RSS; when the findings change it reads the findings' causes and errors (input
# 105–156) over Modbus with mbpoll (within ≈ 1 s of wall clock: some simulated minutes later),
# and prints each cause's error on its largest axis. Prints one markdown table row per cycle.
# Usage: bench/health_work_cycles.sh BUILD_DIR HOURS CYCLE[,CYCLE…]|all [--sim-effect SPEC]…
set -euo pipefail
BUILD=${1:?build dir}
HOURS=${2:?hours}
CYCLES=${3:?cycles}
shift 3
FTD="$BUILD/bin/ftd"
[ -x "$FTD" ] || { echo "health_work_cycles: no $FTD (build the ftd target)" >&2; exit 1; }
[ "$CYCLES" = all ] &&
  CYCLES=machine-tending,palletising,assembly,polishing,hand-guiding,screwdriving,night-idle
RATE=1000
HZ=$(getconf CLK_TCK)
SPAN=$(awk -v h="$HOURS" 'BEGIN { printf "%d", h * 3600 }')
OUT=$(mktemp -d)
trap 'rm -rf "$OUT"' EXIT

PORT=$((15600 + RANDOM % 400))

# Causes (105–108) and errors (109–156) of the active findings: "cause axis error" per finding.
poll() {
  local causes errs
  causes=$(mbpoll -m tcp -p "$PORT" -a 1 -0 -t 3 -r 105 -c 4 -1 -q 127.0.0.1 2>/dev/null) || return 0
  errs=$(mbpoll -m tcp -p "$PORT" -a 1 -0 -t 3:float -B -r 109 -c 24 -1 -q 127.0.0.1 2>/dev/null) ||
    return 0
  paste -d' ' <(echo "$causes" | awk '/^\[/ { print $2 }') \
    <(echo "$errs" | awk '/^\[/ { print $2 }' | paste -d' ' - - - - - -) |
    awk '$1 > 0 { best = 2; for (i = 3; i <= 7; ++i) if ($i * $i > $best * $best) best = i
                  printf "%d:%s=%.4g ", $1, substr("FxFyFzMxMyMz", 2 * best - 3, 2), $best }'
}

echo "| cycle | hours | effects | findings seen | first per cause (simulated s) | error on its largest axis (N, N·m) | coverage at end | CPU s | CPU per simulated s | peak RSS MB |"
echo "|---|---|---|---|---|---|---|---|---|---|"
for cycle in ${CYCLES//,/ }; do
  log="$OUT/$cycle.txt"
  "$FTD" --adc sim --rate-hz "$RATE" --unpaced --seed 1 --sim-profile "work:$cycle" \
    --sim-span-s "$SPAN" --print-hz 100 --modbus-tcp "127.0.0.1:$PORT" "$@" >"$log" \
    2>"$OUT/err.txt" &
  pid=$!
  ticks=0
  rss=0
  last_findings=0x00
  errors=""
  while kill -0 "$pid" 2>/dev/null; do
    sleep 1
    line=$(tail -n 2 "$log" | head -n 1)
    seq=$(echo "$line" | sed -n 's/^seq=\([0-9]*\).*/\1/p')
    findings=$(echo "$line" | sed -n 's/.*findings=\(0x[0-9a-f]*\).*/\1/p')
    if [ -n "$findings" ] && [ "$findings" != "$last_findings" ] && [ "$findings" != 0x00 ]; then
      errors="$errors$(poll)"
    fi
    [ -n "$findings" ] && last_findings=$findings
    ticks=$(awk '{ print $14 + $15 }' "/proc/$pid/stat" 2>/dev/null || echo "$ticks")
    rss=$(awk '/VmHWM/ { print $2 }' "/proc/$pid/status" 2>/dev/null || echo "$rss")
    if [ -n "$seq" ] && [ "$seq" -ge $((SPAN * RATE)) ]; then kill "$pid" 2>/dev/null || true; fi
  done
  wait "$pid" 2>/dev/null || true
  awk -v cycle="$cycle" -v hours="$HOURS" -v effects="${*:-none}" -v rate="$RATE" \
      -v span="$SPAN" -v ticks="$ticks" -v errors="${errors:-—}" -v hz="$HZ" -v rss="$rss" '
    function hex(s,    v, i) {  # "0x1c" → 28 (mawk has no strtonum)
      v = 0
      for (i = 3; i <= length(s); ++i) v = v * 16 + index("0123456789abcdef", tolower(substr(s, i, 1))) - 1
      return v
    }
    /^seq=/ {
      seq = substr($1, 5) + 0
      if (seq > span * rate) next
      for (i = 1; i <= NF; ++i) {
        if ($i ~ /^findings=/) f = hex(substr($i, 10))
        if ($i ~ /^covers=/) cov = substr($i, 8)
      }
      for (b = 0; b < 8; ++b) if (int(f / 2 ^ b) % 2 == 1 && !(b in first)) first[b] = seq / rate
    }
    END {
      firsts = ""
      seen = 0
      for (b = 0; b < 8; ++b) if (b in first) {
        firsts = firsts sprintf("cause %d: %.0f ", b + 1, first[b])
        seen += 2 ^ b
      }
      cpu = ticks / hz
      printf "| %s | %s | %s | 0x%02x | %s | %s | %s | %.0f | %.4f | %.0f |\n", cycle, hours,
             effects, seen, firsts == "" ? "—" : firsts, errors, cov, cpu, cpu / span, rss / 1024
    }' "$log"
done
