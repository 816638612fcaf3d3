#!/usr/bin/env bash
# Installs every build, runtime and test dependency of fieldbridge from Debian 12
# packages. Idempotent: packages already present are left alone, and apt is only
# asked when something is missing. Needs root (or sudo) when it has to install.
# Usage: deploy/install-deps.sh [--arch arm64|armhf]... [--dist trixie]
#   --arch ARCH  also what a cross build for the Debian architecture ARCH needs
#                (docs/build.md, "Cross builds"): the cross compiler, qemu-user, and a
#                target root of the libraries below made by deploy/cross/make-sysroot.
#   --dist DIST  the build root of the Debian release DIST (trixie) instead of this
#                machine: the packages below, from that release, installed into
#                /var/cache/fieldbridge/root/DIST-amd64 by deploy/dist/make-root
#                (docs/build.md, "Debian 13"); on this machine only mmdebstrap.
#                --dist bookworm is this machine (Debian 12): as without --dist.
#   --dist DIST --arch ARCH  the cross root of DIST for ARCH instead (docs/build.md,
#                "Debian 13 on ARM"): the same packages with ARCH added as a foreign
#                architecture, the libraries below also as LIBRARY:ARCH, DIST's cross
#                compiler and qemu-user, in /var/cache/fieldbridge/root/DIST-cross-ARCH.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"

cross_arches=()
dist=bookworm
while [ $# -gt 0 ]; do
  case "$1" in
    --arch) [ $# -ge 2 ] || { echo "install-deps: --arch needs arm64 or armhf" >&2; exit 2; }
            cross_arches+=("$2"); shift 2 ;;
    --dist) [ $# -ge 2 ] || { echo "install-deps: --dist needs bookworm or trixie" >&2; exit 2; }
            dist="$2"; shift 2 ;;
    *) echo "install-deps: unknown argument '$1' (usage: install-deps.sh [--arch arm64|armhf]... [--dist bookworm|trixie])" >&2; exit 2 ;;
  esac
done
case "$dist" in
  bookworm) ;;
  trixie) ;;
  *) echo "install-deps: no build root for Debian release '$dist' (bookworm or trixie)" >&2; exit 2 ;;
esac

# The libraries the build links or includes (docs/dependencies.md says why each one is
# here); a cross build gets the same set for its target in its own root.
libraries=(
  libmodbus-dev libpaho-mqttpp-dev libpaho-mqtt-dev libssl-dev libyaml-cpp-dev
  libsystemd-dev doctest-dev nlohmann-json3-dev libasio-dev libspdlog-dev libfmt-dev
  libcli11-dev libmicrohttpd-dev libprotobuf-c-dev
)
# Those a target architecture needs its own of (Multi-Arch: same); the headers-only
# ones are Architecture: all, one package for every architecture.
arch_libraries=()
for p in "${libraries[@]}"; do
  case "$p" in doctest-dev|nlohmann-json3-dev|libasio-dev|libcli11-dev) ;; *) arch_libraries+=("$p") ;; esac
done
packages=(
  # toolchain
  build-essential cmake ninja-build g++ pkg-config
  ccache  # every build on this machine and in the build roots (deploy/compiler-cache.sh)
  clang libclang-rt-14-dev  # the fuzz build (tests/fuzz): clang++ and its libFuzzer
  protobuf-c-compiler  # protoc-c: the Sparkplug B schema's C code, generated at build time
  "${libraries[@]}"
  # test and demo tools
  socat mosquitto mosquitto-clients mbpoll curl python3 python3-pymodbus
  protobuf-compiler python3-protobuf  # the tests' own Sparkplug B decoder (tests/support)
  prometheus  # promtool check metrics (tests/integration/gateway/test_metrics.py)
  python3-serial-asyncio procps  # pymodbus.client imports serial_asyncio (a Recommends)
  # Debian packages (deploy/build-deb) and their test (tests/package/test-package.sh):
  # systemd for systemd-analyze and systemd-sysusers, man-db for man --warnings
  debhelper dpkg-dev lintian man-db systemd
)
root_packages=()
if [ "$dist" != bookworm ]; then
  # The build root's packages: the list above from that release, without the fuzz
  # build's clang (the campaign runs on Debian 12 only), with ccache (the root's builds
  # use the cache of deploy/dist/in-root) and strace (docs/performance.md) last: the
  # list is the root's stamp, and its order unchanged keeps existing roots.
  for p in "${packages[@]}"; do
    case "$p" in clang|libclang-rt-*|ccache) ;; *) root_packages+=("$p") ;; esac
  done
  root_packages+=(ccache strace)
  packages=(mmdebstrap)
fi
for arch in "${cross_arches[@]}"; do
  case "$arch" in
    arm64|armhf) ;;
    *) echo "install-deps: no cross build for '$arch' (arm64 or armhf)" >&2; exit 2 ;;
  esac
  # The compiler runs here (amd64 packages); the target's libraries come from its root;
  # qemu-user runs the target's programs (the tests, --version); mmdebstrap makes the root.
  # In a release's cross root all three are that release's, installed in the root.
  [ "$dist" != bookworm ] || packages+=("crossbuild-essential-$arch" qemu-user mmdebstrap)
done

missing=()
for p in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

make_sysroots() {
  local arch
  if [ ${#root_packages[@]} -eq 0 ]; then
    for arch in "${cross_arches[@]}"; do
      "$here/deploy/cross/make-sysroot" "$arch" "${libraries[@]}"
    done
  elif [ ${#cross_arches[@]} -eq 0 ]; then
    "$here/deploy/dist/make-root" "$dist" amd64 "${root_packages[@]}"
  else
    # The release's cross roots: the build root's packages, the cross compiler, the
    # emulator, and the target's libraries (multiarch: LIBRARY:ARCH).
    for arch in "${cross_arches[@]}"; do
      "$here/deploy/dist/make-root" --foreign "$arch" "$dist" amd64 "${root_packages[@]}" \
        "crossbuild-essential-$arch" qemu-user "${arch_libraries[@]/%/:$arch}"
    done
  fi
}

if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages present"
  make_sysroots
  exit 0
fi

SUDO=""
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO="sudo"; else
    echo "install-deps: missing packages (${missing[*]}) and not root; run as root or install sudo" >&2
    exit 1
  fi
fi

echo "install-deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
# The Debian mosquitto package starts a system broker on port 1883; tests and the
# demo start their own broker on a private loopback port, so the system one is
# not needed and is left as the package set it up.
# Likewise the prometheus package (wanted for promtool only) sets up a system
# Prometheus server on port 9090; the tests do not use it.
make_sysroots
