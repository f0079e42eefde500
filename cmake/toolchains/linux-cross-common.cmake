# Shared part of the Linux cross toolchain files: Debian cross compiler, package sysroot, qemu-user.
#
# Expects FTSTACK_TRIPLET (aarch64-linux-gnu, arm-linux-gnueabihf), FTSTACK_DEB_ARCH (arm64, armhf),
# FTSTACK_QEMU (qemu-aarch64, qemu-arm) and CMAKE_SYSTEM_PROCESSOR from the including file.
# The C library and libstdc++ are the cross compiler's own (/usr/<triplet>); the target's -dev
# packages (libmodbus, libgpiod, gtest, header-only Eigen/json/CLI11) come from a sysroot folder made
# by cmake/make-sysroot.sh, passed as -DFTSTACK_SYSROOT=... (default: out/sysroot-<arch>).
set(CMAKE_SYSTEM_NAME Linux)

set(CMAKE_C_COMPILER ${FTSTACK_TRIPLET}-gcc)
set(CMAKE_CXX_COMPILER ${FTSTACK_TRIPLET}-g++)
set(CMAKE_STRIP ${FTSTACK_TRIPLET}-strip CACHE FILEPATH "strip for the target")

get_filename_component(_ftstack_root "${CMAKE_CURRENT_LIST_DIR}/../.." ABSOLUTE)
if(NOT FTSTACK_SYSROOT)
  if(DEFINED ENV{FTSTACK_SYSROOT})
    set(FTSTACK_SYSROOT "$ENV{FTSTACK_SYSROOT}")
  else()
    set(FTSTACK_SYSROOT "${_ftstack_root}/out/sysroot-${FTSTACK_DEB_ARCH}")
  endif()
endif()
set(FTSTACK_SYSROOT "${FTSTACK_SYSROOT}" CACHE PATH "target package sysroot (cmake/make-sysroot.sh)")
# try_compile projects see only these variables; keep the sysroot and triplet across.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES FTSTACK_SYSROOT)
if(NOT EXISTS "${FTSTACK_SYSROOT}/usr/include/modbus")
  message(FATAL_ERROR "No target sysroot at ${FTSTACK_SYSROOT}: run "
                      "cmake/make-sysroot.sh ${FTSTACK_DEB_ARCH} first")
endif()

# Search the cross compiler's tree and the package sysroot, never the host's /usr for the target.
set(CMAKE_FIND_ROOT_PATH "/usr/${FTSTACK_TRIPLET}" "${FTSTACK_SYSROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)
set(CMAKE_LIBRARY_ARCHITECTURE ${FTSTACK_TRIPLET})

# pkg-config: only the target's .pc files, paths rewritten into the sysroot.
set(ENV{PKG_CONFIG_DIR} "")
set(ENV{PKG_CONFIG_LIBDIR}
    "${FTSTACK_SYSROOT}/usr/lib/${FTSTACK_TRIPLET}/pkgconfig:${FTSTACK_SYSROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${FTSTACK_SYSROOT}")

# Multiarch headers of the sysroot (e.g. openssl/opensslconf.h, which cpp-httplib's header pulls in):
# the host compiler searches /usr/include/<triplet> by itself, the cross compiler does not.
string(APPEND CMAKE_CXX_FLAGS_INIT " -isystem ${FTSTACK_SYSROOT}/usr/include/${FTSTACK_TRIPLET}")
string(APPEND CMAKE_C_FLAGS_INIT " -isystem ${FTSTACK_SYSROOT}/usr/include/${FTSTACK_TRIPLET}")

# Libraries of the sysroot that other libraries pull in at link time.
set(_ftstack_libdir "${FTSTACK_SYSROOT}/usr/lib/${FTSTACK_TRIPLET}")
# zlib (which cpp-httplib's library links) sits in /lib/<triplet>, not /usr/lib/<triplet>.
set(_ftstack_rootlibdir "${FTSTACK_SYSROOT}/lib/${FTSTACK_TRIPLET}")
string(APPEND CMAKE_EXE_LINKER_FLAGS_INIT
       " -Wl,-rpath-link,${_ftstack_libdir} -Wl,-rpath-link,${_ftstack_rootlibdir}")
string(APPEND CMAKE_SHARED_LINKER_FLAGS_INIT
       " -Wl,-rpath-link,${_ftstack_libdir} -Wl,-rpath-link,${_ftstack_rootlibdir}")

# Run target programs (tests, gtest discovery) through qemu-user. -L gives the cross C library;
# LD_LIBRARY_PATH keeps the loader on that one C library (a mixed one makes threads spin forever).
find_program(FTSTACK_QEMU_PROGRAM ${FTSTACK_QEMU})
if(FTSTACK_QEMU_PROGRAM)
  set(CMAKE_CROSSCOMPILING_EMULATOR
      "${FTSTACK_QEMU_PROGRAM};-L;/usr/${FTSTACK_TRIPLET};-E;LD_LIBRARY_PATH=/usr/${FTSTACK_TRIPLET}/lib:${_ftstack_libdir}")
endif()
