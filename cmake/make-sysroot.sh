#!/usr/bin/env bash
# make-sysroot.sh — target sysroot for cross builds from downloaded Debian packages, no system change.
#
#   cmake/make-sysroot.sh arm64|armhf [DIR]      (default DIR: out/sysroot-ARCH in the repository)
#
# Uses a private APT configuration (APT_CONFIG) with its own state, cache and sources (bookworm and
# bookworm-updates, no security suite: its armhf index is what breaks multiarch on this machine),
# runs `apt-get update` / `apt-get download` for the target architecture and unpacks the packages
# with `dpkg -x`. The system's apt configuration, dpkg database and architectures are untouched.
# The C library and libstdc++ come from Debian's cross compiler (/usr/<triplet>), not from here.
set -euo pipefail

arch=${1:-}
case "$arch" in
  arm64) triplet=aarch64-linux-gnu ;;
  armhf) triplet=arm-linux-gnueabihf ;;
  *) echo "usage: $0 arm64|armhf [DIR]" >&2; exit 2 ;;
esac
root=$(cd "$(dirname "$0")/.." && pwd)
dir=${2:-$root/out/sysroot-$arch}
mirror=${FTSTACK_DEBIAN_MIRROR:-http://deb.debian.org/debian}
suite=${FTSTACK_DEBIAN_SUITE:-bookworm}

# Target -dev packages and the runtime libraries they link (the tests run these under qemu); ftd's
# MQTT: libmosquitto (with the libssl3 and libcjson1 it links) and protobuf-c; ftd's web server:
# cpp-httplib (its library links OpenSSL, zlib and brotli, whose -dev packages its .pc requires).
packages=(libmodbus-dev libmodbus5 libgpiod-dev libgpiod2 libgtest-dev libgmock-dev googletest
  libeigen3-dev nlohmann-json3-dev libcli11-dev libfmt-dev libfmt9
  libbenchmark-dev libbenchmark1debian
  libmosquitto-dev libmosquitto1 libcjson1 libssl3 libprotobuf-c-dev libprotobuf-c1
  libcpp-httplib-dev libcpp-httplib0.11 libssl-dev libbrotli-dev libbrotli1 zlib1g-dev zlib1g)

stamp="$dir/.ftstack-sysroot"
want="$arch ${packages[*]}"
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$want" ]; then
  echo "sysroot $dir is up to date" >&2
  exit 0
fi

apt_dir="$dir.apt"
mkdir -p "$apt_dir"/{etc/apt.conf.d,etc/preferences.d,state/lists/partial,cache/archives/partial,debs} "$dir"
: > "$apt_dir/state/status"
cat > "$apt_dir/etc/sources.list" <<SRC
deb [arch=$arch signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] $mirror $suite main
deb [arch=$arch signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] $mirror $suite-updates main
SRC
cat > "$apt_dir/apt.conf" <<CONF
APT::Architecture "$arch";
APT::Architectures { "$arch"; };
Dir::Etc "$apt_dir/etc";
Dir::Etc::sourcelist "$apt_dir/etc/sources.list";
Dir::Etc::sourceparts "-";
Dir::Etc::preferencesparts "$apt_dir/etc/preferences.d";
Dir::State "$apt_dir/state";
Dir::State::status "$apt_dir/state/status";
Dir::Cache "$apt_dir/cache";
Acquire::Languages "none";
CONF
# As root, apt drops to the _apt user for downloads, which cannot write to a private folder.
[ "$(id -u)" -eq 0 ] && echo 'APT::Sandbox::User "root";' >> "$apt_dir/apt.conf"
export APT_CONFIG="$apt_dir/apt.conf"

echo "[sysroot] apt-get update ($arch, private configuration $APT_CONFIG)" >&2
apt-get -q update >&2
echo "[sysroot] downloading ${packages[*]}" >&2
(cd "$apt_dir/debs" && rm -f ./*.deb && apt-get -q download "${packages[@]}" >&2)
for deb in "$apt_dir"/debs/*.deb; do
  dpkg -x "$deb" "$dir"
done

# Absolute symlinks inside the packages (e.g. lib*.so -> /usr/lib/...) must point into the sysroot.
while IFS= read -r link; do
  target=$(readlink "$link")
  case "$target" in
    /*) ln -sfn "$dir$target" "$link" ;;
  esac
done < <(find "$dir" -type l)

echo "$want" > "$stamp"
echo "[sysroot] ready: $dir ($triplet)" >&2
