# Sourced by tests/package/test-package.sh --dist DIST (not run alone), as root on this
# machine, with check, contains, $here, $dist, $arch, $deb, $sim_deb, $upstream_version
# set: the packages installed by apt into a clean, minimal root of that release.
#
# The minimal root (mmdebstrap --variant=apt: Essential, apt and nothing else) is made
# once into /var/cache/fieldbridge/root/<dist>-<arch>-minimal (deploy/dist/make-root),
# then copied afresh for each run into a throwaway directory: apt there sees only the
# release's archive and the two files, so every library the packages need must come from
# their Depends. The copy is deleted at the end.
minimal_name="$dist-$arch-minimal"
"$here/deploy/dist/make-root" --name "$minimal_name" "$dist" "$arch"
minimal="$("$here/deploy/dist/make-root" --name "$minimal_name" --path "$dist" "$arch")"
clean="$(mktemp -d -p /var/tmp)"
trap 'rm -rf "$clean"' EXIT
cp -a "$minimal/." "$clean/"
in_clean() { "$here/deploy/dist/in-root" --root "$clean" "$dist" "$@"; }
# in-root gives the root a fresh /tmp: the packages go in through /var/tmp.
mkdir -p "$clean/var/tmp/packages"
cp "$deb" "$sim_deb" "$clean/var/tmp/packages/"
check "clean $dist root: apt-get install of both packages (Depends resolved from Debian $dist alone)" \
  in_clean env DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends \
    "/var/tmp/packages/$(basename "$deb")" "/var/tmp/packages/$(basename "$sim_deb")"
check "clean $dist root: fieldbridge --version" \
  contains "$(in_clean /usr/bin/fieldbridge --version 2>&1)" "^fieldbridge $upstream_version\$"
check "clean $dist root: fieldbridge --check-config /etc/fieldbridge/fieldbridge.yaml as user fieldbridge" \
  in_clean runuser -u fieldbridge -- /usr/bin/fieldbridge --check-config /etc/fieldbridge/fieldbridge.yaml
check "clean $dist root: every library of fieldbridge and fieldbridge-sim found (ldd)" \
  lacks "$(in_clean ldd /usr/bin/fieldbridge /usr/bin/fieldbridge-sim 2>&1)" 'not found'
check "clean $dist root: libmicrohttpd (loaded with dlopen) installed through Depends" \
  contains "$(in_clean sh -c 'ls /usr/lib/*/libmicrohttpd.so.12' 2>&1)" 'libmicrohttpd\.so\.12$'
rm -rf "$clean"
trap - EXIT
