# A cross build in a release's cross root (deploy/dist/make-root --foreign, entered with
# deploy/dist/in-root --arch; docs/build.md, "Debian 13 on ARM"), included by
# debian-sysroot.cmake: the target's libraries are the root's own, installed for the
# target architecture beside the machine's (Debian's multiarch: /usr/lib/<triplet>,
# /usr/include/<triplet>), which Debian's cross compiler searches without a sysroot.
# CMake finds the target's libraries and CMake packages there through
# CMAKE_LIBRARY_ARCHITECTURE; programs are the machine's.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)

# pkg-config (libmodbus, libsystemd, libmicrohttpd) reads the target's .pc files only,
# as <triplet>-pkg-config does.
set(PKG_CONFIG_EXECUTABLE /usr/bin/pkg-config CACHE FILEPATH "pkg-config, run with the target's .pc files" FORCE)
set(ENV{PKG_CONFIG_DIR} "")
set(ENV{PKG_CONFIG_PATH} "")
set(ENV{PKG_CONFIG_LIBDIR} "/usr/lib/${FIELDBRIDGE_CROSS_TRIPLET}/pkgconfig:/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_SYSROOT_DIR} "")

# ctest runs the target's test executables under qemu-user; the target's loader and
# libraries are where the programs look for them (/usr/lib/<triplet>), so no -L.
set(CMAKE_CROSSCOMPILING_EMULATOR ${FIELDBRIDGE_CROSS_QEMU})
