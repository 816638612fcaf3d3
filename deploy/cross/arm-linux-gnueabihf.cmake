# Cross build for Debian armhf, 32-bit ARMv7 with hardware floating point (docs/build.md,
# "Cross builds"):
#   cmake -DCMAKE_TOOLCHAIN_FILE=deploy/cross/arm-linux-gnueabihf.cmake ...
set(CMAKE_SYSTEM_PROCESSOR arm)
set(FIELDBRIDGE_CROSS_TRIPLET arm-linux-gnueabihf)
set(FIELDBRIDGE_CROSS_DEBIAN_ARCH armhf)
set(FIELDBRIDGE_CROSS_QEMU qemu-arm)
include(${CMAKE_CURRENT_LIST_DIR}/debian-sysroot.cmake)
