# Cross-compiling for arm64 (AArch64) with Debian's cross toolchain (g++-aarch64-linux-gnu) against an arm64 root
# of Debian's own packages (tools/build-arm64.sh makes it with mmdebstrap). Executables run through qemu-user, so
# that gtest_discover_tests and ctest work on this machine.
#   cmake -S . -B build-arm64 -DCMAKE_TOOLCHAIN_FILE=cmake/aarch64-linux-gnu.cmake -DMCSLAM_ARM64_ROOT=<root>
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

# The toolchain file is read again for every try_compile: the root travels in the environment too.
if(NOT MCSLAM_ARM64_ROOT AND DEFINED ENV{MCSLAM_ARM64_ROOT})
  set(MCSLAM_ARM64_ROOT "$ENV{MCSLAM_ARM64_ROOT}")
endif()
if(NOT MCSLAM_ARM64_ROOT OR NOT EXISTS "${MCSLAM_ARM64_ROOT}/usr/include/aarch64-linux-gnu")
  message(FATAL_ERROR "MCSLAM_ARM64_ROOT='${MCSLAM_ARM64_ROOT}' is not an arm64 root (tools/build-arm64.sh makes one)")
endif()
set(MCSLAM_ARM64_ROOT "${MCSLAM_ARM64_ROOT}" CACHE PATH "The arm64 root the build compiles and links against")
set(ENV{MCSLAM_ARM64_ROOT} "${MCSLAM_ARM64_ROOT}")

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_SYSROOT "${MCSLAM_ARM64_ROOT}")
set(CMAKE_FIND_ROOT_PATH "${MCSLAM_ARM64_ROOT}")
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# pkg-config reads the root's .pc files and prefixes their paths with it.
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${MCSLAM_ARM64_ROOT}")
set(ENV{PKG_CONFIG_LIBDIR}
    "${MCSLAM_ARM64_ROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${MCSLAM_ARM64_ROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_PATH} "")

# -L: the emulated dynamic loader finds the root's libraries (the root's /lib is its own).
find_program(MCSLAM_QEMU_AARCH64 qemu-aarch64-static REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR "${MCSLAM_QEMU_AARCH64};-L;${MCSLAM_ARM64_ROOT}")
