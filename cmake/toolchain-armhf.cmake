# Cross-compiling for the unit's 32-bit ARM processor with Debian's armhf toolchain (make check-arm):
#   cmake -S . -B build-arm -DCMAKE_TOOLCHAIN_FILE=cmake/toolchain-armhf.cmake -DSF_CORE_ONLY=ON
# Needs crossbuild-essential-armhf, qemu-user and libcmocka-dev:armhf (tools/deps.sh installs them).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(SF_ARM_TRIPLE arm-linux-gnueabihf)
set(CMAKE_C_COMPILER ${SF_ARM_TRIPLE}-gcc)
set(CMAKE_CXX_COMPILER ${SF_ARM_TRIPLE}-g++)

# Libraries and headers: the cross C library lives in /usr/arm-linux-gnueabihf; the armhf cmocka is a
# multiarch package (/usr/lib/arm-linux-gnueabihf, found through CMAKE_LIBRARY_ARCHITECTURE, which
# CMake reads from the compiler); cmocka.h in /usr/include is one file for every architecture. Never a
# host (x86-64) library; programs (cmake, python) are the host's.
set(CMAKE_FIND_ROOT_PATH /usr/${SF_ARM_TRIPLE})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)

# ctest runs every test executable through qemu's user-mode emulator. -L points it at the cross C
# library's dynamic loader; libcmocka.so.0 is then found in /usr/lib/arm-linux-gnueabihf, which qemu
# reaches through to the host's file system.
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-arm;-L;/usr/${SF_ARM_TRIPLE})
