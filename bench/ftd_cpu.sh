#!/usr/bin/env bash
# ftd's whole CPU (all threads, user + system) at a sample rate, with and without the health watch
# side by side — and, given a second ftd binary (e.g. one built from an earlier commit), that one
# with the watch in the same windows: each repetition starts the daemons at once (`--adc sim`,
# paced, no clients), lets them settle, then reads utime + stime from /proc/PID/stat over the same
# window. Prints every repetition and the median, min and max per variant, in % of one host core.
# Usage: bench/ftd_cpu.sh [BUILD_DIR] [RATE_HZ] [REPS] [WINDOW_S] [BASELINE_FTD]
set -euo pipefail
BUILD=${1:-build}
RATE=${2:-8000}
REPS=${3:-5}
WINDOW=${4:-10}
BASELINE=${5:-}
FTD="$BUILD/bin/ftd"
[ -x "$FTD" ] || { echo "ftd_cpu: no $FTD (build the ftd target)" >&2; exit 1; }
[ -z "$BASELINE" ] || [ -x "$BASELINE" ] || { echo "ftd_cpu: no $BASELINE" >&2; exit 1; }
HZ=$(getconf CLK_TCK)

# utime + stime of PID, in clock ticks (the split between the two is tick-sampled and too coarse
# at these loads to print).
ticks() { awk '{ print $14 + $15 }' "/proc/$1/stat"; }

pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; }
trap cleanup EXIT

start() {  # BINARY [EXTRA ARGS…]: one paced daemon in the background
  "$1" --adc sim --rate-hz "$RATE" --print-hz 0 --modbus-tcp 127.0.0.1:0 "${@:2}" >/dev/null 2>&1 &
}

with=()
without=()
base=()
for rep in $(seq 1 "$REPS"); do
  start "$FTD"
  on=$!
  start "$FTD" --no-health-watch
  off=$!
  pids=("$on" "$off")
  if [ -n "$BASELINE" ]; then
    start "$BASELINE"
    old=$!
    pids+=("$old")
  fi
  sleep 2  # start-up (sensor model, calibration) is not the steady state
  a0=$(ticks "$on"); b0=$(ticks "$off"); c0=0
  [ -z "$BASELINE" ] || c0=$(ticks "$old")
  t0=$(date +%s.%N)
  sleep "$WINDOW"
  a1=$(ticks "$on"); b1=$(ticks "$off"); c1=0
  [ -z "$BASELINE" ] || c1=$(ticks "$old")
  t1=$(date +%s.%N)
  kill "${pids[@]}"; wait "${pids[@]}" 2>/dev/null || true
  pids=()
  pct() { awk -v d="$1" -v hz="$HZ" -v t0="$t0" -v t1="$t1" 'BEGIN { printf "%.2f", 100 * d / hz / (t1 - t0) }'; }
  w=$(pct $((a1 - a0))); n=$(pct $((b1 - b0))); o=$(pct $((c1 - c0)))
  with+=("$w"); without+=("$n"); base+=("$o")
  extra=""
  [ -z "$BASELINE" ] || extra=", baseline with the watch $o %"
  printf '  rep %d/%d at %s Hz over %s s: with the watch %s %%, without %s %%%s  (load average %s)\n' \
    "$rep" "$REPS" "$RATE" "$WINDOW" "$w" "$n" "$extra" "$(cut -d' ' -f1 /proc/loadavg)"
done

summary() {
  printf '%s\n' "${@:2}" | sort -g | awk -v name="$1" '{ v[NR] = $1 }
    END { m = NR % 2 ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2
          printf "  %-28s median %.2f %%  min %.2f %%  max %.2f %% of a core (%d runs)\n", name, m, v[1], v[NR], NR }'
}
summary "with the watch" "${with[@]}"
summary "without the watch" "${without[@]}"
[ -z "$BASELINE" ] || summary "baseline, with the watch" "${base[@]}"
