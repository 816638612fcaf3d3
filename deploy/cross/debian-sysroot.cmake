# The part of the cross toolchain files that is the same for every target
# (aarch64-linux-gnu.cmake, arm-linux-gnueabihf.cmake set FIELDBRIDGE_CROSS_TRIPLET and
# FIELDBRIDGE_CROSS_QEMU, then include this). Debian's cross compiler
# (crossbuild-essential-<arch>) compiles against the target root that
# deploy/cross/make-sysroot unpacked; CMake finds libraries, headers and CMake packages
# only there, programs only here. docs/build.md, "Cross builds".
#
# The root: $FIELDBRIDGE_SYSROOT if set, else /var/cache/fieldbridge/sysroot/bookworm-<arch>.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_C_COMPILER ${FIELDBRIDGE_CROSS_TRIPLET}-gcc)
set(CMAKE_CXX_COMPILER ${FIELDBRIDGE_CROSS_TRIPLET}-g++)
set(CMAKE_LIBRARY_ARCHITECTURE ${FIELDBRIDGE_CROSS_TRIPLET})

# In a release's cross root (deploy/dist/in-root --arch; docs/build.md, "Debian 13 on
# ARM") the target's libraries are installed beside the machine's (multiarch): there is
# no target root to point at.
if("$ENV{FIELDBRIDGE_ROOT_FOREIGN_ARCH}" STREQUAL "${FIELDBRIDGE_CROSS_DEBIAN_ARCH}")
  include(${CMAKE_CURRENT_LIST_DIR}/debian-multiarch.cmake)
  return()
endif()

if(DEFINED ENV{FIELDBRIDGE_SYSROOT})
  set(FIELDBRIDGE_SYSROOT "$ENV{FIELDBRIDGE_SYSROOT}")
elseif(NOT FIELDBRIDGE_SYSROOT)
  set(FIELDBRIDGE_SYSROOT /var/cache/fieldbridge/sysroot/bookworm-${FIELDBRIDGE_CROSS_DEBIAN_ARCH})
endif()
if(NOT EXISTS "${FIELDBRIDGE_SYSROOT}/.fieldbridge-sysroot")
  message(FATAL_ERROR "No target root for ${FIELDBRIDGE_CROSS_DEBIAN_ARCH} in ${FIELDBRIDGE_SYSROOT}: "
    "make it with `deploy/install-deps.sh --arch ${FIELDBRIDGE_CROSS_DEBIAN_ARCH}` (as root), "
    "or point FIELDBRIDGE_SYSROOT at one")
endif()
# try_compile() projects read this file again: they get the same root.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES FIELDBRIDGE_SYSROOT)

set(CMAKE_SYSROOT "${FIELDBRIDGE_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH "${FIELDBRIDGE_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config (libmodbus, libsystemd, libmicrohttpd) reads the target's .pc files only,
# and prefixes the root to the paths they give. This machine's pkg-config does it:
# Debian 12 has no <triplet>-pkg-config (debhelper names one; this overrides it).
set(PKG_CONFIG_EXECUTABLE /usr/bin/pkg-config CACHE FILEPATH "pkg-config, run with the target root's .pc files" FORCE)
set(ENV{PKG_CONFIG_DIR} "")
set(ENV{PKG_CONFIG_PATH} "")
set(ENV{PKG_CONFIG_LIBDIR}
    "${FIELDBRIDGE_SYSROOT}/usr/lib/${FIELDBRIDGE_CROSS_TRIPLET}/pkgconfig:${FIELDBRIDGE_SYSROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${FIELDBRIDGE_SYSROOT}")

# ctest runs the target's test executables under qemu-user with the root as its file
# system prefix (the loader and the shared libraries come from there); there is no
# binfmt_misc here, so the emulator is named, not implied.
set(CMAKE_CROSSCOMPILING_EMULATOR ${FIELDBRIDGE_CROSS_QEMU} -L ${FIELDBRIDGE_SYSROOT})
