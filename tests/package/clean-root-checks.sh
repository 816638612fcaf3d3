# Sourced by tests/package/test-package.sh --dist DIST (not run alone), as root on this
# machine, with check, contains, lacks, $here, $dist, $arch, $native, $deb, $sim_deb,
# $upstream_version set: the packages installed by apt into a clean, minimal root of
# that release.
#
# The minimal root (mmdebstrap --variant=apt: Essential, apt and nothing else) is made
# once into /var/cache/fieldbridge/root/<dist>-<arch>-minimal (deploy/dist/make-root),
# then copied afresh for each run into a throwaway directory: apt there sees only the
# release's archive and the two files, so every library the packages need must come from
# their Depends. The copy is deleted at the end.
#
# For arm64 and armhf (--dist DIST --arch ARCH) the minimal root is this machine's
# architecture with ARCH added (dpkg --add-architecture, as on a multiarch box; make-root
# --foreign), <dist>-cross-<arch>-minimal, with qemu-user besides (static, it brings no
# library): apt installs the ARCH packages and resolves their Depends with the release's
# ARCH packages alone, their maintainer scripts run (shell and this machine's
# systemd-sysusers), and the installed program runs under qemu-user.
case "$arch" in
  "$native") minimal_args=(--name "$dist-$arch-minimal" "$dist" "$arch") run=() list=(ldd) ;;
  arm64) run=(qemu-aarch64) list=(qemu-aarch64 /lib/ld-linux-aarch64.so.1 --list) ;;
  armhf) run=(qemu-arm) list=(qemu-arm /lib/ld-linux-armhf.so.3 --list) ;;
esac
[ "$arch" = "$native" ] || minimal_args=(--foreign "$arch" --name "$dist-cross-$arch-minimal" "$dist" "$native")
triplet="$(dpkg-architecture -a"$arch" -qDEB_HOST_MULTIARCH 2>/dev/null)"
if [ "$arch" = "$native" ]; then
  "$here/deploy/dist/make-root" "${minimal_args[@]}"
else
  "$here/deploy/dist/make-root" "${minimal_args[@]}" qemu-user
fi
minimal="$("$here/deploy/dist/make-root" --path "${minimal_args[@]}")"
clean="$(mktemp -d -p /var/tmp)"
trap 'rm -rf "$clean"' EXIT
cp -a "$minimal/." "$clean/"
in_clean() { "$here/deploy/dist/in-root" --root "$clean" "$dist" "$@"; }
# in-root gives the root a fresh /tmp: the packages go in through /var/tmp.
mkdir -p "$clean/var/tmp/packages"
cp "$deb" "$sim_deb" "$clean/var/tmp/packages/"
check "clean $dist root: apt-get install of both $arch packages (Depends resolved from Debian $dist alone)" \
  in_clean env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
    "/var/tmp/packages/$(basename "$deb")" "/var/tmp/packages/$(basename "$sim_deb")"
check "clean $dist root: fieldbridge --version${run:+ under ${run[*]}}" \
  contains "$(in_clean "${run[@]}" /usr/bin/fieldbridge --version 2>&1)" "^fieldbridge $upstream_version\$"
check "clean $dist root: fieldbridge --check-config /etc/fieldbridge/fieldbridge.yaml as user fieldbridge${run:+ under ${run[*]}}" \
  in_clean runuser -u fieldbridge -- "${run[@]}" /usr/bin/fieldbridge --check-config /etc/fieldbridge/fieldbridge.yaml
check "clean $dist root: every library of fieldbridge and fieldbridge-sim found (${list[*]})" \
  lacks "$(for program in fieldbridge fieldbridge-sim; do in_clean "${list[@]}" "/usr/bin/$program" 2>&1 || echo "$program: exit $? (not found)"; done)" 'not found'
check "clean $dist root: libmicrohttpd (loaded with dlopen) installed through Depends" \
  test -f "$clean/usr/lib/$triplet/libmicrohttpd.so.12"
rm -rf "$clean"
trap - EXIT
