# Cross toolchain for arm-linux-gnueabihf with Debian's cross compiler and multiarch :armhf libraries.
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR arm)
set(BOTICELLI_TRIPLET arm-linux-gnueabihf)

set(CMAKE_C_COMPILER ${BOTICELLI_TRIPLET}-gcc)
set(CMAKE_CXX_COMPILER ${BOTICELLI_TRIPLET}-g++)

# Libraries and headers come from the multiarch folders (/usr/lib/arm-linux-gnueabihf,
# /usr/include/arm-linux-gnueabihf); headers that are the same on every architecture (Eigen) from
# /usr/include. Programs (pkg-config, code generators) run on the host.
set(CMAKE_FIND_ROOT_PATH /usr/${BOTICELLI_TRIPLET})
set(CMAKE_LIBRARY_ARCHITECTURE ${BOTICELLI_TRIPLET})
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)

# pkg-config must read the target's .pc files, not the host's.
set(ENV{PKG_CONFIG_LIBDIR} /usr/lib/${BOTICELLI_TRIPLET}/pkgconfig:/usr/share/pkgconfig)
set(ENV{PKG_CONFIG_PATH} "")

# ctest runs the target's test binaries through qemu with the target's loader and libc.
set(CMAKE_CROSSCOMPILING_EMULATOR qemu-arm;-L;/usr/${BOTICELLI_TRIPLET})
