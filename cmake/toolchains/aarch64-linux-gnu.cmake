# Cross build for arm64 (aarch64) Linux with Debian's cross compiler (crossbuild-essential-arm64)
# against a sysroot of Debian's arm64 packages: scripts/cross-arm64.sh makes one and passes it as
# SURROUNDD_SYSROOT. Test programs run under qemu-user (qemu-user-static), which ctest and
# gtest_discover_tests put in front of them, and testing::ChildProcess in front of the project's
# programs that a test starts (tests/support/child_process.hpp).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

if(NOT SURROUNDD_SYSROOT)
  set(SURROUNDD_SYSROOT "$ENV{SURROUNDD_SYSROOT}")
endif()
if(NOT IS_DIRECTORY "${SURROUNDD_SYSROOT}/usr/lib/aarch64-linux-gnu")
  message(FATAL_ERROR "SURROUNDD_SYSROOT='${SURROUNDD_SYSROOT}' is no arm64 sysroot: "
                      "scripts/cross-arm64.sh makes one")
endif()
# try_compile projects see only what is listed here.
list(APPEND CMAKE_TRY_COMPILE_PLATFORM_VARIABLES SURROUNDD_SYSROOT)

set(CMAKE_SYSROOT "${SURROUNDD_SYSROOT}")
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

# Programs from the build machine, everything else from the sysroot only.
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE ONLY)

# By its full path: tests start the project's programs through it with execv (no PATH search).
find_program(SURROUNDD_QEMU_AARCH64 qemu-aarch64-static REQUIRED)
set(CMAKE_CROSSCOMPILING_EMULATOR "${SURROUNDD_QEMU_AARCH64}" -L "${SURROUNDD_SYSROOT}")

# pkg-config reads the sysroot's .pc files and prefixes their paths with it.
set(ENV{PKG_CONFIG_DIR} "")
set(ENV{PKG_CONFIG_LIBDIR}
    "${SURROUNDD_SYSROOT}/usr/lib/aarch64-linux-gnu/pkgconfig:${SURROUNDD_SYSROOT}/usr/share/pkgconfig")
set(ENV{PKG_CONFIG_SYSROOT_DIR} "${SURROUNDD_SYSROOT}")
