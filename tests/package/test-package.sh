#!/usr/bin/env bash
# The Debian packages end to end, on this machine (Debian 12, as root or with sudo):
# builds fieldbridge and fieldbridge-sim with deploy/build-deb, installs them with apt,
# checks the service user, the files, the conffile, the configuration check, the units
# (systemd-analyze verify), the man pages and lintian, then edits the conffile, removes
# the packages (the edit stays) and purges them (it goes).
#
# systemd need not be PID 1 (CI runs in a container): the maintainer scripts create the
# user with systemd-sysusers, which works without a running systemd, and skip starting
# units; systemd-analyze verify reads the installed unit files offline. What needs a
# running systemd (systemctl start) is not tested here.
#
# The machine is left as it was found: an exit trap purges both packages and deletes
# the user and group if this script's install created them. It refuses to run when
# either package is already installed.
#
# With --arch arm64 or armhf, the packages cross-built for that architecture
# (deploy/build-deb --arch, docs/build.md "Cross builds"), which this machine cannot
# install: their architecture, lintian, the Depends computed from the target's
# libraries, the same files as this machine's packages (built first when they are
# not there), and the packaged fieldbridge and fieldbridge-sim run under qemu-user:
# --version, --check-config on the packaged configuration, --help, and the demo cell's
# Modbus TCP reads and writes through the packaged daemon against this machine's
# simulator (tests/integration/gateway/test_modbus_devices.py).
#
# With --dist trixie, the Debian 13 amd64 packages (deploy/build-deb --dist trixie, built
# in the Debian 13 build root): every check above run inside that root (deploy/dist/
# in-root), which has Debian 13's apt, systemd, lintian and test tools, then the
# packages installed by apt into a clean, minimal Debian 13 root of their own (a fresh
# copy each run; tests/package/clean-root-checks.sh): apt resolves their Depends from
# Debian 13 alone, and the packaged fieldbridge checks its packaged configuration there.
#
# With --dist trixie --arch arm64 or armhf, the Debian 13 packages for that architecture
# (deploy/build-deb --dist trixie --arch, built in the Debian 13 cross root): the --arch
# checks above run inside that cross root (Debian 13's lintian and qemu-user, compared
# with the Debian 13 amd64 packages), then the packages are installed by apt into a
# clean Debian 13 root of this machine's architecture with ARCH added (multiarch), where
# apt resolves their Depends from Debian 13's ARCH packages alone and the installed
# programs run under qemu-user (tests/package/clean-root-checks.sh).
#
# Usage: tests/package/test-package.sh [--dist DIST] [--arch ARCH]
#   FIELDBRIDGE_DEB_DIR        where the packages are built (default build-deb/)
#   FIELDBRIDGE_DEB_PREBUILT=1 test the packages already in that directory, no build
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
out="${FIELDBRIDGE_DEB_DIR:-$here/build-deb}"
export FIELDBRIDGE_DEB_DIR="$out"
native="$(dpkg --print-architecture)"
arch="$native" dist=bookworm
while [ $# -gt 0 ]; do
  case "$1" in
    --arch) [ $# -ge 2 ] || { echo "test-package: --arch needs an architecture" >&2; exit 2; }
            arch="$2"; shift 2 ;;
    --dist) [ $# -ge 2 ] || { echo "test-package: --dist needs a Debian release (bookworm or trixie)" >&2; exit 2; }
            dist="$2"; shift 2 ;;
    *) echo "test-package: unknown argument '$1' (usage: test-package.sh [--dist bookworm|trixie] [--arch $native|arm64|armhf])" >&2; exit 2 ;;
  esac
done
build_args=(--arch "$arch") build_name="$arch"
if [ "$dist" != bookworm ]; then build_args=(--dist "$dist" --arch "$arch") build_name="$dist-$arch"; fi

started=$SECONDS
if [ "${FIELDBRIDGE_DEB_PREBUILT:-0}" != 1 ]; then
  mkdir -p "$out"
  build_started=$SECONDS
  log="$out/build-deb-$build_name.log"
  "$here/deploy/build-deb" "${build_args[@]}" > "$log" 2>&1 || { tail -50 "$log" >&2; echo "test-package: deploy/build-deb ${build_args[*]} failed (log: $log)" >&2; exit 1; }
  echo "test-package: deploy/build-deb ${build_args[*]} took $((SECONDS - build_started)) s (log: $log)"
fi
# 0.2.0~deb12 (deploy/package-version); the programs say 0.2.0.
version="$("$here/deploy/package-version")"
upstream_version="${version%%~*}"
deb="$out/fieldbridge_${version}_${arch}.deb"
sim_deb="$out/fieldbridge-sim_${version}_${arch}.deb"

passed=0; failed=0
check() {  # check DESCRIPTION COMMAND...: run it, count it, show its output when it fails
  local description="$1"; shift
  local output
  if output="$("$@" 2>&1)"; then
    passed=$((passed + 1)); echo "ok   $description"
  else
    failed=$((failed + 1)); echo "FAIL $description"; printf '%s\n' "$output" | sed 's/^/     /'
  fi
}
silent() {  # silent COMMAND...: succeeds when COMMAND exits 0 and prints nothing
  local output
  output="$("$@" 2>&1)" || { printf '%s\n' "$output"; return 1; }
  [ -z "$output" ] || { printf 'unexpected output:\n%s\n' "$output"; return 1; }
}
contains() {  # contains TEXT PATTERN: grep -E PATTERN in TEXT, TEXT shown when it is not there
  grep -Eq -- "$2" <<<"$1" || { printf 'no /%s/ in:\n%s\n' "$2" "$1"; return 1; }
}
lacks() { ! grep -Eq -- "$2" <<<"$1" || { printf '/%s/ found in:\n%s\n' "$2" "$1"; return 1; }; }

if [ "$dist" != bookworm ] && [ -z "${FIELDBRIDGE_IN_ROOT:-}" ]; then
  # The checks below inside the release's build root (for arm64 and armhf its cross
  # root, with the cross checks), then the clean root's.
  root_args=()
  [ "$arch" = "$native" ] || root_args=(--arch "$arch")
  FIELDBRIDGE_DEB_PREBUILT=1 "$here/deploy/dist/in-root" "${root_args[@]}" "$dist" \
    "$here/tests/package/test-package.sh" "${root_args[@]}"
  version="$("$here/deploy/dist/in-root" "${root_args[@]}" "$dist" "$here/deploy/package-version")"
  deb="$out/fieldbridge_${version}_${arch}.deb"
  sim_deb="$out/fieldbridge-sim_${version}_${arch}.deb"
  upstream_version="${version%%~*}"
  . "$here/tests/package/clean-root-checks.sh"
  echo "test-package: $((SECONDS - started)) s in all"
  echo "package ($dist $arch, clean root): $passed passed, $failed failed"
  [ "$failed" -eq 0 ]
  exit
fi
check "both packages built: $(basename "$deb") $(basename "$sim_deb")" test -f "$deb" -a -f "$sim_deb"
check "lintian: no error or warning" lintian --fail-on error,warning --display-info "$deb" "$sim_deb"
check "dependencies computed by dpkg-shlibdeps (libmodbus, paho, yaml-cpp, libsystemd)" \
  contains "$(dpkg-deb -f "$deb" Depends)" 'libmodbus5.*libpaho-mqttpp3-1.*libsystemd0.*libyaml-cpp0'
# Each release's own library packages: the names that differ between Debian 12 and 13;
# and where its units go (deploy/build-deb).
case "$version" in
  *~deb12) release_libraries=('libyaml-cpp0\.7' 'libfmt9' 'libmicrohttpd12 ') unit_dir=/lib/systemd/system ;;
  *) release_libraries=('libyaml-cpp0\.8' 'libfmt10' 'libmicrohttpd12t64 ') unit_dir=/usr/lib/systemd/system ;;
esac
for library in "${release_libraries[@]}"; do
  check "dependencies: ${library//[\\ ]/} of Debian ${version##*~deb}" contains "$(dpkg-deb -f "$deb" Depends)" "(^|, )$library"
done

if [ "$arch" != "$native" ]; then
  . "$here/tests/package/cross-checks.sh"
  echo "test-package: $((SECONDS - started)) s in all"
  echo "package ($arch): $passed passed, $failed failed"
  [ "$failed" -eq 0 ]
  exit
fi

SUDO=()
if [ "$(id -u)" -ne 0 ]; then
  if command -v sudo >/dev/null 2>&1; then SUDO=(sudo); else
    echo "test-package: installs packages with apt-get: run as root or install sudo" >&2
    exit 1
  fi
fi
as_root() { "${SUDO[@]}" "$@"; }

installed() {  # installed PACKAGE: dpkg knows it in any state but not-installed (config-files too)
  local status
  status="$(dpkg-query -W -f='${Status}' "$1" 2>/dev/null)" || return 1
  [ -n "$status" ] && [ "${status##* }" != not-installed ]
}
for p in fieldbridge fieldbridge-sim; do
  if installed "$p"; then
    echo "test-package: $p is already installed (or its configuration is left); this test installs and" \
         "purges it. Purge it first: apt-get purge $p" >&2
    exit 1
  fi
done
user_existed=0; getent passwd fieldbridge >/dev/null && user_existed=1
group_existed=0; getent group fieldbridge >/dev/null && group_existed=1

cleanup() {
  local rc=$?
  rm -f "${definition_config:-}"
  for p in fieldbridge-sim fieldbridge; do
    if installed "$p"; then as_root env DEBIAN_FRONTEND=noninteractive apt-get purge -y -qq "$p" >/dev/null || rc=1; fi
  done
  # Debian leaves system users in place on purge; this test removes the one it made.
  if [ "$user_existed" = 0 ] && getent passwd fieldbridge >/dev/null; then as_root userdel fieldbridge || rc=1; fi
  if [ "$group_existed" = 0 ] && getent group fieldbridge >/dev/null; then as_root groupdel fieldbridge || rc=1; fi
  exit $rc
}
trap cleanup EXIT

check "apt-get install ./fieldbridge_*.deb ./fieldbridge-sim_*.deb" \
  as_root env DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$deb" "$sim_deb"

check "user fieldbridge: system user, no login shell" \
  contains "$(getent passwd fieldbridge)" '^fieldbridge:x:[0-9]{1,3}:[0-9]+:.*:(/usr/sbin/nologin|/sbin/nologin)$'
check "user fieldbridge: groups fieldbridge and dialout" contains " $(id -nG fieldbridge) " ' fieldbridge .*dialout |.* dialout .*fieldbridge '
for f in /usr/bin/fieldbridge /usr/bin/fieldbridge-sim "$unit_dir/fieldbridge.service" \
         /usr/lib/sysusers.d/fieldbridge.conf /etc/fieldbridge/fieldbridge.yaml \
         /usr/share/man/man8/fieldbridge.8.gz /usr/share/man/man5/fieldbridge.yaml.5.gz \
         /usr/share/man/man1/fieldbridge-sim.1.gz /usr/share/doc/fieldbridge/copyright; do
  check "installed: $f" test -f "$f"
done
check "installed: $unit_dir/fieldbridge.socket" contains "$(dpkg -L fieldbridge)" "^$unit_dir/fieldbridge\.socket\$"
check "docs: the operations guide service.md in /usr/share/doc/fieldbridge" \
  contains "$(dpkg -L fieldbridge)" '^/usr/share/doc/fieldbridge/service\.md'
check "conffile: /etc/fieldbridge/fieldbridge.yaml" \
  contains "$(dpkg-query -W -f='${Conffiles}' fieldbridge)" '^ /etc/fieldbridge/fieldbridge\.yaml [0-9a-f]{32}$'
check "conffile is the commented example" cmp /etc/fieldbridge/fieldbridge.yaml "$here/config/fieldbridge.example.yaml"
check "fieldbridge --version" contains "$(fieldbridge --version)" "^fieldbridge $upstream_version\$"
check "fieldbridge --check-config /etc/fieldbridge/fieldbridge.yaml (as user fieldbridge): exit 0" \
  as_root runuser -u fieldbridge -- /usr/bin/fieldbridge --check-config /etc/fieldbridge/fieldbridge.yaml
check "fieldbridge-sim --help" /usr/bin/fieldbridge-sim --help
check "installed: the shipped device definitions in /usr/share/fieldbridge/devices" \
  test -f /usr/share/fieldbridge/devices/example-thermostat.yaml
for builtin in hiwin-xeg excd203mb wtec-rtu wtec-ascii; do
  check "installed: the built-in type's definition $builtin.yaml in /usr/share/fieldbridge/devices, as shipped" \
    cmp "/usr/share/fieldbridge/devices/$builtin.yaml" "$here/config/devices/$builtin.yaml"
done
check "docs: the definition guide devices.md in /usr/share/doc/fieldbridge" \
  contains "$(dpkg -L fieldbridge)" '^/usr/share/doc/fieldbridge/devices\.md'
# A device of a shipped definition, with no definitions: key: found in the default
# directories (docs/devices.md).
definition_config="$(mktemp -p /tmp --suffix=.yaml)"
printf '%s\n' 'gateway: {id: pkg}' 'lines:' '  - name: a' '    port: /dev/ttyS0' '    devices:' \
  '      - {name: room, type: example-thermostat, address: 7, unit_id: 1}' > "$definition_config"
chmod 0644 "$definition_config"
check "fieldbridge --check-config: type example-thermostat found in /usr/share/fieldbridge/devices" \
  as_root runuser -u fieldbridge -- /usr/bin/fieldbridge --check-config "$definition_config"
rm -f "$definition_config"
# Spec section 7 on the shipped build: reloads leave a running line's idle time within
# one transaction of its normal idle time (the same test runs in ctest with the
# sanitizer build's looser bounds).
check "hitless reload on the installed binaries: no failed request, no reopened port, no gap over one transaction" \
  env FIELDBRIDGE_RELEASE_BUILD=1 PYTHONPATH="$here/tests/integration/gateway:$here/tests/integration/sim:$here/tests/integration" \
  /usr/bin/python3 "$here/tests/integration/gateway/test_hitless_reload.py" \
  --gateway /usr/bin/fieldbridge --sim /usr/bin/fieldbridge-sim
# The demo cell (tests/integration/gateway/gatewaylib.py: two lines, four devices) read
# and written over Modbus TCP through the installed daemon and simulator.
check "the demo cell's Modbus TCP reads and writes through the installed daemon" \
  env PYTHONDONTWRITEBYTECODE=1 \
  PYTHONPATH="$here/tests/integration/gateway:$here/tests/integration/sim:$here/tests/integration" \
  /usr/bin/python3 "$here/tests/integration/gateway/test_modbus_devices.py" \
  --gateway /usr/bin/fieldbridge --sim /usr/bin/fieldbridge-sim
check "systemd-analyze verify on the installed units: silent" \
  silent systemd-analyze verify "$unit_dir"/fieldbridge.*
check "the service is installed but not enabled" \
  test ! -e /etc/systemd/system/multi-user.target.wants/fieldbridge.service
# What a running systemd would do, read from the maintainer scripts dh_installsystemd wrote.
check "postinst: starts or restarts the unit through deb-systemd-invoke (no disabled unit is started)" \
  contains "$(cat /var/lib/dpkg/info/fieldbridge.postinst)" "deb-systemd-invoke \\\$_dh_action 'fieldbridge.service'"
check "prerm: stops the service on remove" \
  contains "$(cat /var/lib/dpkg/info/fieldbridge.prerm)" "deb-systemd-invoke stop 'fieldbridge.service'"
for page in /usr/share/man/man8/fieldbridge.8.gz /usr/share/man/man5/fieldbridge.yaml.5.gz \
            /usr/share/man/man1/fieldbridge-sim.1.gz; do
  check "man --warnings: $(basename "$page")" \
    silent env LC_ALL=C.UTF-8 MANWIDTH=80 sh -c 'man --warnings -E UTF-8 -l "$1" >/dev/null' man "$page"
done

edit="# edited by tests/package/test-package.sh"
as_root sh -c "echo '$edit' >> /etc/fieldbridge/fieldbridge.yaml"
check "apt-get remove fieldbridge fieldbridge-sim" \
  as_root env DEBIAN_FRONTEND=noninteractive apt-get remove -y -qq fieldbridge fieldbridge-sim
check "after remove: /usr/bin/fieldbridge is gone" test ! -e /usr/bin/fieldbridge
check "after remove: the edited conffile stays" grep -qxF "$edit" /etc/fieldbridge/fieldbridge.yaml
check "after remove: fieldbridge is in state config-files" \
  contains "$(dpkg-query -W -f='${Status}' fieldbridge)" 'deinstall ok config-files'
check "apt-get purge fieldbridge" as_root env DEBIAN_FRONTEND=noninteractive apt-get purge -y -qq fieldbridge
check "after purge: /etc/fieldbridge is gone" test ! -e /etc/fieldbridge
check "after purge: no unit left" test ! -e "$unit_dir/fieldbridge.service"

echo "test-package: $((SECONDS - started)) s in all"
echo "package: $passed passed, $failed failed"
[ "$failed" -eq 0 ]
