# CMake toolchain for 32-bit ARM hard-float Linux boards (Raspberry Pi OS 32-bit, BeagleBone, ...).
# Needs g++-arm-linux-gnueabihf, qemu-user (tests) and a sysroot from `cmake/make-sysroot.sh armhf`.
set(CMAKE_SYSTEM_PROCESSOR armv7l)
set(FTSTACK_TRIPLET arm-linux-gnueabihf)
set(FTSTACK_DEB_ARCH armhf)
set(FTSTACK_QEMU qemu-arm)
include(${CMAKE_CURRENT_LIST_DIR}/linux-cross-common.cmake)
