# The checks of tests/package/test-package.sh --arch ARCH on packages cross-built for
# ARCH (arm64, armhf), which this machine cannot install: sourced by test-package.sh
# after its common checks, with its helpers (check, contains) and $here, $out,
# $version, $arch, $native, $deb, $sim_deb set. Run on this machine (Debian 12) or, for
# a release's packages (--dist trixie --arch), inside that release's cross root.

case "$arch" in
  arm64) qemu=qemu-aarch64; elf='Class: +ELF64.*Machine: +AArch64' ;;
  armhf) qemu=qemu-arm; elf='Class: +ELF32.*Machine: +ARM.*Flags: .*hard-float' ;;
  *) echo "test-package: no cross checks for '$arch' (arm64 or armhf)" >&2; exit 2 ;;
esac
if [ -n "${FIELDBRIDGE_IN_ROOT:-}" ]; then
  # A release's cross root (deploy/dist/in-root --arch): the target's loader and
  # libraries are installed there (multiarch), where the programs look for them.
  emulator=("$qemu")
else
  sysroot="${FIELDBRIDGE_SYSROOT:-$("$here/deploy/cross/make-sysroot" --path "$arch")}"
  emulator=("$qemu" -L "$sysroot")
fi

# This machine's packages: what the cross-built ones must hold, and the simulator the
# packaged daemon is tested against.
native_deb="$out/fieldbridge_${version}_${native}.deb"
native_sim_deb="$out/fieldbridge-sim_${version}_${native}.deb"
if [ ! -f "$native_deb" ] || [ ! -f "$native_sim_deb" ]; then
  native_log="$out/build-deb-$native.log"
  echo "test-package: building the $native packages to compare with (log: $native_log)"
  "$here/deploy/build-deb" > "$native_log" 2>&1 || { tail -50 "$native_log" >&2; echo "test-package: deploy/build-deb failed (log: $native_log)" >&2; exit 1; }
fi

unpacked="$(mktemp -d)"
trap 'rm -rf "$unpacked"' EXIT
dpkg-deb -x "$deb" "$unpacked/$arch"
dpkg-deb -x "$sim_deb" "$unpacked/$arch"
dpkg-deb -x "$native_sim_deb" "$unpacked/$native"

files() { dpkg-deb -c "$1" | awk '{print $6}' | sort; }
for pair in "$deb:$native_deb" "$sim_deb:$native_sim_deb"; do
  cross_pkg="${pair%%:*}"; native_pkg="${pair#*:}"
  check "dpkg-deb --info $(basename "$cross_pkg"): Architecture: $arch" \
    contains "$(dpkg-deb --info "$cross_pkg")" "^ Architecture: $arch\$"
  check "$(basename "$cross_pkg") holds the files of $(basename "$native_pkg")" \
    diff <(files "$native_pkg") <(files "$cross_pkg")
done
check "dependencies of the $arch package are the $native package's (one set of libraries)" \
  test "$(dpkg-deb -f "$deb" Depends | sed 's/ *([^)]*)//g')" = "$(dpkg-deb -f "$native_deb" Depends | sed 's/ *([^)]*)//g')"
for binary in fieldbridge fieldbridge-sim; do
  check "/usr/bin/$binary is an $arch program" \
    contains "$(readelf -h "$unpacked/$arch/usr/bin/$binary" | tr '\n' ' ')" "$elf"
done

check "fieldbridge --version under $qemu" \
  contains "$("${emulator[@]}" "$unpacked/$arch/usr/bin/fieldbridge" --version 2>&1)" "^fieldbridge $upstream_version\$"
check "fieldbridge --check-config on the packaged /etc/fieldbridge/fieldbridge.yaml under $qemu: exit 0" \
  "${emulator[@]}" "$unpacked/$arch/usr/bin/fieldbridge" --check-config "$unpacked/$arch/etc/fieldbridge/fieldbridge.yaml"
check "fieldbridge-sim --help under $qemu" "${emulator[@]}" "$unpacked/$arch/usr/bin/fieldbridge-sim" --help
# The demo cell (tests/integration/gateway/gatewaylib.py: two lines, four devices) read
# and written over Modbus TCP through the packaged daemon, emulated, with this
# machine's simulator on the pseudo-terminals.
check "the demo cell's Modbus TCP reads and writes through the packaged $arch daemon under $qemu" \
  env FIELDBRIDGE_TEST_EMULATOR="${emulator[*]}" PYTHONDONTWRITEBYTECODE=1 \
  PYTHONPATH="$here/tests/integration/gateway:$here/tests/integration/sim:$here/tests/integration" \
  /usr/bin/python3 "$here/tests/integration/gateway/test_modbus_devices.py" \
  --gateway "$unpacked/$arch/usr/bin/fieldbridge" --sim "$unpacked/$native/usr/bin/fieldbridge-sim"
echo "     installed size: $(dpkg-deb -f "$deb" Installed-Size) KiB for $arch, $(dpkg-deb -f "$native_deb" Installed-Size) KiB for $native (fieldbridge); $(dpkg-deb -f "$sim_deb" Installed-Size) and $(dpkg-deb -f "$native_sim_deb" Installed-Size) KiB (fieldbridge-sim)"
