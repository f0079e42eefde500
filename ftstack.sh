#!/usr/bin/env bash
# ftstack.sh — set-up and entry point: installs missing Debian packages, configures, builds, runs.
#   ./ftstack.sh run  [ftd options]   simulated sensor daemon, Modbus TCP on 127.0.0.1:1502
#   ./ftstack.sh test                 the whole test suite
#   ./ftstack.sh sanitize             the whole suite under ASan+UBSan (build-debug/)
#   ./ftstack.sh build | deps | bench
set -euo pipefail
cd "$(dirname "$0")"
ROOT=$(pwd)
BUILD_DIR=${FTSTACK_BUILD_DIR:-$ROOT/build}

# Every Debian package the project needs (build, tests, reports, real Modbus/serial clients).
PACKAGES=(build-essential cmake ninja-build pkg-config ccache
  libeigen3-dev libmodbus-dev libgpiod-dev gpiod
  libgtest-dev libgmock-dev libbenchmark-dev
  nlohmann-json3-dev libcli11-dev libfmt-dev
  mbpoll socat gnuplot-nox chromium
  calculix-ccx gmsh python3-gmsh python3-numpy)

log() { printf '[ftstack] %s\n' "$*" >&2; }

deps() {
  local missing=()
  for p in "${PACKAGES[@]}"; do
    if ! dpkg-query -W -f='${Status}\n' "$p" 2>/dev/null | grep -q '^install ok installed'; then
      missing+=("$p")
    fi
  done
  [ ${#missing[@]} -eq 0 ] && return 0
  log "installing missing Debian packages: ${missing[*]}"
  local sudo=""
  [ "$(id -u)" -ne 0 ] && sudo="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $sudo apt-get -o DPkg::Lock::Timeout=600 update -q || log "apt-get update failed; trying anyway"
  $sudo apt-get -o DPkg::Lock::Timeout=600 install -y -q --no-install-recommends "${missing[@]}"
}

build() {
  deps
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    log "configuring $BUILD_DIR"
    cmake -S "$ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DFTSTACK_WERROR=ON
  fi
  log "building (progress below)"
  cmake --build "$BUILD_DIR" -j "$(nproc)"
}

cmd=${1:-help}
shift || true
case "$cmd" in
  deps) deps ;;
  build) build ;;
  run)
    build
    log "starting the simulated sensor daemon; poll it with:"
    log "  mbpoll -m tcp -p 1502 -a 1 -t 3:float -B -r 7 -c 6 -1 127.0.0.1   (README: more examples)"
    exec "$BUILD_DIR/bin/ftd" --adc sim --modbus-tcp 127.0.0.1:1502 "$@"
    ;;
  test)
    build
    log "running the test suite"
    cd "$BUILD_DIR"
    exec ctest --output-on-failure -j "$(nproc)" --timeout 600 "$@"
    ;;
  sanitize)
    deps
    DBG=$ROOT/build-debug
    if [ ! -f "$DBG/CMakeCache.txt" ]; then
      cmake --preset host-debug
    fi
    log "building everything (host code included) with AddressSanitizer + UndefinedBehaviorSanitizer"
    cmake --build "$DBG" -j "$(nproc)"
    cd "$DBG"
    exec ctest --output-on-failure -j "$(nproc)" --timeout 600 "$@"
    ;;
  bench)
    build
    exec "$ROOT/bench/run.sh" "$BUILD_DIR" "$@"
    ;;
  *)
    sed -n '2,6p' "$0" | sed 's/^# \{0,1\}//'
    [ "$cmd" = help ] || exit 2
    ;;
esac
