# Cross build for 64-bit ARM Linux (Debian's aarch64-linux-gnu toolchain and arm64 -dev
# packages: bash scripts/install-deps.sh aarch64). Tests run under qemu-user:
#   cmake --preset aarch64 && cmake --build --preset aarch64 && ctest --preset aarch64
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)

set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)

# Libraries and CMake packages of the target come from the arm64 multiarch directories; the
# headers that are the same on every architecture stay in /usr/include, which the cross compiler
# searches itself.
set(CMAKE_FIND_ROOT_PATH /usr/lib/aarch64-linux-gnu /usr/aarch64-linux-gnu)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)

# pkg-config: the arm64 .pc files only.
set(ENV{PKG_CONFIG_LIBDIR} /usr/lib/aarch64-linux-gnu/pkgconfig:/usr/share/pkgconfig)
set(ENV{PKG_CONFIG_SYSROOT_DIR} "")

# Target programs (tests, gtest_discover_tests' listing, the CLI in CLI tests) run under qemu.
# The dynamic loader must come from the same glibc build as the libc it loads. The programs link
# arm64 multiarch libraries (libc6:arm64 and the -dev packages), and the loader searches
# /lib/aarch64-linux-gnu first, so it finds the multiarch libc; the loader must then be the
# multiarch one too (prefix /). The cross toolchain's own loader (prefix /usr/aarch64-linux-gnu,
# libc6-arm64-cross, another Debian revision) with the multiarch libc spins for ever in
# pthread_create: every program that starts a thread (TBB: every render) never finishes.
if(EXISTS /lib/ld-linux-aarch64.so.1)
    set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64 -L /)
else()
    set(CMAKE_CROSSCOMPILING_EMULATOR qemu-aarch64 -L /usr/aarch64-linux-gnu)
endif()
