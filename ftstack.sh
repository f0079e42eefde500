#!/usr/bin/env bash
# ftstack.sh — set-up and entry point: installs missing Debian packages, configures, builds, runs.
#   ./ftstack.sh run  [ftd options]   simulated sensor daemon, Modbus TCP on 127.0.0.1:1502, page on :8080
#   ./ftstack.sh test                 the whole test suite
#   ./ftstack.sh sanitize             every test of compiled code under ASan+UBSan (build-debug/)
#   ./ftstack.sh mqtt-demo            a local mosquitto and two simulated sensors publishing Sparkplug B
#   ./ftstack.sh build | deps | bench
set -euo pipefail
cd "$(dirname "$0")"
ROOT=$(pwd)
BUILD_DIR=${FTSTACK_BUILD_DIR:-$ROOT/build}

# Every Debian package the project needs (build, tests, reports, real Modbus/serial clients, MQTT:
# the broker, libmosquitto, protobuf-c for Sparkplug B and the tests' independent Python decoder;
# numpy for the independent real-recording generator and analysis under tests/; CalculiX and
# gmsh for the design explorer's FE check, libgmsh-dev for its CAD export (ftsim design --step);
# rt-tests' cyclictest as the host's latency reference
# in bench/web_load.py).
PACKAGES=(build-essential cmake ninja-build pkg-config ccache
  libeigen3-dev libmodbus-dev libgpiod-dev gpiod
  libgtest-dev libgmock-dev libbenchmark-dev
  nlohmann-json3-dev libcli11-dev libfmt-dev
  mbpoll socat gnuplot-nox chromium libcpp-httplib-dev
  mosquitto mosquitto-clients libmosquitto-dev libprotobuf-c-dev protobuf-c-compiler
  protobuf-compiler python3-paho-mqtt python3-protobuf python3-numpy openssl
  calculix-ccx gmsh python3-gmsh libgmsh-dev valgrind rt-tests)

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

# The npm test clients from their lock files, each into its own folder: the web page's browser test
# (tests/web) and the OPC UA client (tests/opcua).
# Node comes from Debian unless one is already installed.
web_test_deps() {
  if ! command -v npm >/dev/null 2>&1; then
    local sudo=""
    [ "$(id -u)" -ne 0 ] && sudo="sudo"
    log "installing nodejs and npm for the web page's browser test"
    DEBIAN_FRONTEND=noninteractive $sudo apt-get -o DPkg::Lock::Timeout=600 install -y -q \
      --no-install-recommends nodejs npm || { log "no npm: the browser test will be skipped"; return 0; }
  fi
  local dir
  # tests/web: the page's browser test (puppeteer-core); tests/opcua: the OPC UA client (node-opcua).
  for dir in web opcua; do
    local lock="$ROOT/tests/$dir/package-lock.json" stamp="$ROOT/tests/$dir/node_modules/.ftstack-lock"
    if [ ! -f "$stamp" ] || ! cmp -s "$lock" "$stamp"; then
      log "installing the $dir tests' npm packages (tests/$dir, npm ci)"
      (cd "$ROOT/tests/$dir" && npm ci --no-audit --no-fund --loglevel=error) &&
        cp "$lock" "$stamp" || log "npm ci failed in tests/$dir: its tests will be skipped"
    fi
  done
}

build() {
  deps
  web_test_deps
  if [ ! -f "$BUILD_DIR/CMakeCache.txt" ]; then
    log "configuring $BUILD_DIR"
    cmake -S "$ROOT" -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release -DFTSTACK_WERROR=ON
  fi
  log "building (progress below)"
  cmake --build "$BUILD_DIR" -j "$(nproc)"
}

# Two simulated sensors publishing Sparkplug B to the broker on 127.0.0.1:1883: the one already
# there, else a mosquitto started here (stopped by its PID with the sensors on Ctrl-C).
mqtt_demo() {
  local pids=() port=1883 dir
  dir=$(mktemp -d)
  trap 'kill "${pids[@]}" 2>/dev/null; wait; rm -rf "$dir"' EXIT
  trap 'exit 0' INT TERM
  if (exec 3<>/dev/tcp/127.0.0.1/$port) 2>/dev/null; then
    log "using the MQTT broker already on 127.0.0.1:$port"
  else
    printf 'listener %s 127.0.0.1\nallow_anonymous true\npersistence false\nuser %s\nlog_type error\nlog_type warning\n' \
      "$port" "$(id -un)" > "$dir/mosquitto.conf"
    PATH="/usr/sbin:$PATH" mosquitto -c "$dir/mosquitto.conf" & pids+=($!)
    sleep 0.5
    log "started mosquitto on 127.0.0.1:$port (PID ${pids[0]})"
  fi
  local w
  for s in a b; do
    [ "$s" = a ] && w=10,0,-50,0,0.5,0 || w=-5,20,-120,0.2,0,0.1
    "$BUILD_DIR/bin/ftd" --adc sim --sim-wrench "$w" --print-hz 0 --mqtt "mqtt://127.0.0.1:$port" \
      --edge-node "demo-$s" --device sensor --seed "$([ "$s" = a ] && echo 1 || echo 2)" "$@" & pids+=($!)
  done
  log "two edge nodes publish: spBv1.0/ftstack/{NBIRTH,NDEATH}/demo-a|demo-b, {DBIRTH,DDATA}/demo-a|demo-b/sensor; watch them with:"
  log "  mosquitto_sub -h 127.0.0.1 -p $port -t 'spBv1.0/ftstack/#' -F '%I %t %l bytes'"
  log "Ctrl-C stops the sensors (they publish NDEATH)${pids[2]:+ and the broker}"
  wait
}

cmd=${1:-help}
shift || true
case "$cmd" in
  deps) deps; web_test_deps ;;
  build) build ;;
  run)
    build
    log "starting the simulated sensor daemon; poll it with:"
    log "  mbpoll -m tcp -p 1502 -a 1 -t 3:float -B -r 7 -c 6 -1 127.0.0.1   (README: more examples)"
    log "or open the web page: http://127.0.0.1:8080/   (docs/web.md)"
    exec "$BUILD_DIR/bin/ftd" --adc sim --modbus-tcp 127.0.0.1:1502 --http 127.0.0.1:8080 "$@"
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
    # Tests labelled python-only run none of our compiled code: nothing for a sanitizer to check.
    # Tests labelled sanitize-redundant run code other tests already run under the sanitizers.
    exec ctest --output-on-failure -j "$(nproc)" --timeout 600 -LE 'python-only|sanitize-redundant' "$@"
    ;;
  mqtt-demo)
    build
    mqtt_demo "$@"
    ;;
  bench)
    build
    exec "$ROOT/bench/run.sh" "$BUILD_DIR" "$@"
    ;;
  *)
    sed -n '2,7p' "$0" | sed 's/^# \{0,1\}//'
    [ "$cmd" = help ] || exit 2
    ;;
esac
