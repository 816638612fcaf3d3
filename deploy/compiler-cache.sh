# Sourced (not run) by deploy/run-tests, deploy/run-demo, deploy/build-deb and tests/fuzz/run-fuzzers
# before they configure a new build directory on this machine: the compilers run
# through ccache (docs/build.md, "Compiler cache"), one cache per machine in
# /var/cache/fieldbridge/ccache/host, shared by the sanitizer, fuzz, cross and package
# builds of every checkout. A build root's builds have their own cache
# (deploy/dist/in-root sets it up; this file leaves them alone).
# FIELDBRIDGE_CCACHE=0 turns it off; without ccache installed it does nothing.
# Expects $here: the checkout's top directory.
if [ -z "${FIELDBRIDGE_IN_ROOT:-}" ] && [ "${FIELDBRIDGE_CCACHE:-1}" != 0 ] && command -v ccache >/dev/null; then
  export CCACHE_DIR="${CCACHE_DIR:-/var/cache/fieldbridge/ccache/host}"
  # Paths inside the checkout are hashed relative to it, and the working directory is
  # left out of the hash: two clones share their objects. The cost: an object taken from
  # another clone names that clone's paths in its debug information.
  export CCACHE_BASEDIR="$here" CCACHE_NOHASHDIR=1
  if mkdir -p "$CCACHE_DIR" 2>/dev/null && [ -w "$CCACHE_DIR" ]; then
    export CMAKE_C_COMPILER_LAUNCHER=ccache CMAKE_CXX_COMPILER_LAUNCHER=ccache
  fi
fi
