# CMake toolchain for 64-bit ARM Linux boards (Raspberry Pi 3/4/5 64-bit, i.MX8, RK3399, ...).
# Needs g++-aarch64-linux-gnu, qemu-user (tests) and a sysroot from `cmake/make-sysroot.sh arm64`.
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(FTSTACK_TRIPLET aarch64-linux-gnu)
set(FTSTACK_DEB_ARCH arm64)
set(FTSTACK_QEMU qemu-aarch64)
include(${CMAKE_CURRENT_LIST_DIR}/linux-cross-common.cmake)
