# Cross build for Debian arm64 (docs/build.md, "Cross builds"):
#   cmake -DCMAKE_TOOLCHAIN_FILE=deploy/cross/aarch64-linux-gnu.cmake ...
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(FIELDBRIDGE_CROSS_TRIPLET aarch64-linux-gnu)
set(FIELDBRIDGE_CROSS_DEBIAN_ARCH arm64)
set(FIELDBRIDGE_CROSS_QEMU qemu-aarch64)
include(${CMAKE_CURRENT_LIST_DIR}/debian-sysroot.cmake)
