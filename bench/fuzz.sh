#!/usr/bin/env bash
# Runs every libFuzzer harness of fuzz/ for a while and reports executions, coverage and findings.
# Usage: bench/fuzz.sh [--seconds S | --runs N] [HARNESS…]   (default: 20 s each, all harnesses)
# Builds build-fuzz/ with clang (-DFTSTACK_FUZZ=ON) on first use. Seeds come from fuzz/corpus/<name>
# (copied: the repository's corpus is not modified); a finding is written to build-fuzz/findings/
# and makes the script exit 1 after the table.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$(pwd)
BUILD=${FTSTACK_FUZZ_BUILD_DIR:-$ROOT/build-fuzz}
limit=(-max_total_time=20)
names=()
while [ $# -gt 0 ]; do
  case "$1" in
    --seconds) limit=(-max_total_time="$2"); shift 2 ;;
    --runs) limit=(-runs="$2"); shift 2 ;;
    -h|--help) sed -n '2,5p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) names+=("$1"); shift ;;
  esac
done
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
[ ${#names[@]} -gt 0 ] || names=(recording cal_file ati sensor profile modbus payload rdt)
mkdir -p "$BUILD/findings"
status=0
printf '\n%-10s %10s %8s %8s %8s  %s\n' harness execs exec/s cov ft result
for n in "${names[@]}"; do
  bin="$BUILD/fuzz/fuzz_$n"
  [ -x "$bin" ] || { log "no harness $n"; exit 2; }
  work=$(mktemp -d)
  cp -r "$ROOT/fuzz/corpus/$n/." "$work/"
  args=("${limit[@]}" -artifact_prefix="$BUILD/findings/$n-" -print_final_stats=1 -rss_limit_mb=2048
        -timeout=10)
  [ -n "${dict[$n]:-}" ] && args+=(-dict="$ROOT/fuzz/dict/${dict[$n]}.dict")
  log "$n: ${limit[*]}"
  set +e
  ASAN_OPTIONS=detect_leaks=1 "$bin" "${args[@]}" "$work" > "$BUILD/findings/$n.log" 2>&1
  rc=$?
  set -e
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$BUILD/findings/$n.log" | grep -o '[0-9]*$' || echo 0)
  speed=$(grep -o 'stat::average_exec_per_sec: *[0-9]*' "$BUILD/findings/$n.log" | grep -o '[0-9]*$' || echo 0)
  last=$(grep -E '^#[0-9]+.*cov: ' "$BUILD/findings/$n.log" | tail -1)
  cov=$(sed -n 's/.*cov: \([0-9]*\).*/\1/p' <<<"$last")
  ft=$(sed -n 's/.*ft: \([0-9]*\).*/\1/p' <<<"$last")
  if [ $rc -eq 0 ]; then result="no findings"; else result="FINDING (see $BUILD/findings/$n.log)"; status=1; fi
  printf '%-10s %10s %8s %8s %8s  %s\n' "$n" "${execs:-0}" "${speed:-0}" "${cov:-?}" "${ft:-?}" "$result"
  rm -rf "$work"
done
exit $status
