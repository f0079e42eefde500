#!/usr/bin/env bash
# Runs every libFuzzer harness of fuzz/ for a while and reports executions, coverage and findings.
# Usage: bench/fuzz.sh [--seconds S] [--runs N] [--keep DIR] [HARNESS…]
#   --seconds S  at most S s per harness; --runs N  at most N executions per harness (both: whichever
#   comes first; neither: 20 s each); --keep DIR  keep each grown corpus in DIR/<harness>.
# Builds build-fuzz/ with clang (-DFTSTACK_FUZZ=ON) on first use. Seeds come from fuzz/corpus/<name>
# (copied: the repository's corpus is not modified); a finding is written to build-fuzz/findings/
# and makes the script exit 1 after the table. Progress: the latest libFuzzer status every 30 s.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BUILD=${FTSTACK_FUZZ_BUILD_DIR:-$ROOT/build-fuzz}
limit=()
runs=""
keep=""
names=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) limit+=(-max_total_time="$2"); shift 2 ;;
    --runs) limit+=(-runs="$2"); runs=$2; shift 2 ;;
    --keep) keep=$2; shift 2 ;;
    -h|--help) sed -n '2,8p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) names+=("$1"); shift ;;
  esac
done
[ ${#limit[@]} -gt 0 ] || limit=(-max_total_time=20)
log() { printf '[fuzz] %s\n' "$*" >&2; }
if ! command -v clang++ >/dev/null || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  log "installing clang (libFuzzer)"
  sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get -o DPkg::Lock::Timeout=600 update -q || log "apt-get update failed; trying anyway"
  $sudo apt-get -o DPkg::Lock::Timeout=600 install -y -q --no-install-recommends clang libclang-rt-14-dev
fi
if [ ! -f "$BUILD/CMakeCache.txt" ]; then
  log "configuring $BUILD (clang, libFuzzer, ASan+UBSan)"
  CC=clang CXX=clang++ cmake -S "$ROOT" -B "$BUILD" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DFTSTACK_FUZZ=ON -DFTSTACK_BUILD_TESTS=OFF -DFTSTACK_BUILD_BENCH=OFF >/dev/null
fi
log "building the harnesses (progress below)"
cmake --build "$BUILD" -j "$(nproc)" --target fuzzers
declare -A dict=([recording]=csv [cal_file]=json [sensor]=json [profile]=json [ati]=xml [payload]=json)
[ ${#names[@]} -gt 0 ] || names=(recording cal_file ati sensor profile modbus tcp_frame payload rdt opcua)
# Input size caps (bytes): each is above the largest seed of its format, so every seed runs whole.
declare -A max_len=([recording]=4096 [cal_file]=4096 [ati]=2048 [sensor]=4096 [profile]=1024
                    [payload]=2048 [rdt]=1024 [modbus]=512 [tcp_frame]=2048 [opcua]=4096)
mkdir -p "$BUILD/findings"
status=0
table=$(printf '%-10s %10s %8s %8s %8s %8s  %s' harness execs exec/s cov ft findings result)
child=""
trap '[ -n "$child" ] && kill "$child" 2>/dev/null; exit 130' INT TERM
for n in "${names[@]}"; do
  bin="$BUILD/fuzz/fuzz_$n"
  [ -x "$bin" ] || { log "no harness $n"; exit 2; }
  work=$(mktemp -d)
  cp -r "$ROOT/fuzz/corpus/$n/." "$work/"
  args=("${limit[@]}" -artifact_prefix="$BUILD/findings/$n-" -print_final_stats=1 -rss_limit_mb=2048
        -timeout=10 -max_len="${max_len[$n]:-4096}")
  [ -n "${dict[$n]:-}" ] && args+=(-dict="$ROOT/fuzz/dict/${dict[$n]}.dict")
  log "$n: ${limit[*]} -max_len=${max_len[$n]:-4096} (log: $BUILD/findings/$n.log)"
  before=$(find "$BUILD/findings" -maxdepth 1 -name "$n-*" | wc -l)
  set +e
  ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:malloc_context_size=0} "$bin" "${args[@]}" "$work" > "$BUILD/findings/$n.log" 2>&1 &
  child=$!
  tick=0
  while kill -0 "$child" 2>/dev/null; do
    sleep 1
    tick=$((tick + 1))
    if [ $((tick % 30)) -eq 0 ]; then
      log "$n: $(grep -aE '^#[0-9]+' "$BUILD/findings/$n.log" | tail -1 | cut -c1-100)"
    fi
  done
  wait "$child"
  rc=$?
  child=""
  set -e
  flog="$BUILD/findings/$n.log"
  execs=$(grep -ao 'stat::number_of_executed_units: *[0-9]*' "$flog" | grep -o '[0-9]*$' || echo 0)
  speed=$(grep -ao 'stat::average_exec_per_sec: *[0-9]*' "$flog" | grep -o '[0-9]*$' || echo 0)
  last=$(grep -aE '^#[0-9]+.*cov: ' "$flog" | tail -1)
  cov=$(sed -n 's/.*cov: \([0-9]*\).*/\1/p' <<<"$last")
  ft=$(sed -n 's/.*ft: \([0-9]*\).*/\1/p' <<<"$last")
  found=$(($(find "$BUILD/findings" -maxdepth 1 -name "$n-*" | wc -l) - before))
  if [ $rc -eq 0 ]; then
    result="no findings"
    if [ -n "$runs" ] && [ "${execs:-0}" -lt "$runs" ]; then result="no findings (time limit before $runs runs)"; fi
  else
    result="FINDING (see $flog)"
    [ "$found" -gt 0 ] || found=1
    status=1
  fi
  row=$(printf '%-10s %10s %8s %8s %8s %8s  %s' "$n" "${execs:-0}" "${speed:-0}" "${cov:-?}" "${ft:-?}" "$found" "$result")
  log "$row"
  table+=$'\n'"$row"
  if [ -n "$keep" ]; then mkdir -p "$keep/$n" && cp -r "$work/." "$keep/$n/"; fi
  rm -rf "$work"
done
printf '\n%s\n' "$table"
exit $status
