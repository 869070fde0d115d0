# Packaging of the rpi4 board: install rules and a CPack .deb (arm64 for the rpi4 preset, armhf for armhf).
include(GNUInstallDirs)
set(BOTICELLI_PACKAGING_DIR ${CMAKE_CURRENT_LIST_DIR})

install(TARGETS boticelli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES ${BOTICELLI_PACKAGING_DIR}/boticelli.service
              ${BOTICELLI_PACKAGING_DIR}/boticelli-can0.service
        DESTINATION lib/systemd/system)
install(FILES ${BOTICELLI_PACKAGING_DIR}/60-boticelli.rules DESTINATION lib/udev/rules.d)
install(FILES ${PROJECT_SOURCE_DIR}/docs/flashing.md ${PROJECT_SOURCE_DIR}/docs/console.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR} OPTIONAL)

if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
  set(BOTICELLI_DEB_ARCH arm64)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^arm")
  set(BOTICELLI_DEB_ARCH armhf)
else()
  execute_process(COMMAND dpkg --print-architecture OUTPUT_VARIABLE BOTICELLI_DEB_ARCH
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME boticelli)
set(CPACK_PACKAGE_VENDOR "Boticelli")
set(CPACK_PACKAGE_CONTACT "Boticelli maintainers <boticelli@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Firmware of the Boticelli exploration robot (Raspberry Pi 4 board)")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${BOTICELLI_DEB_ARCH})
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# Runtime libraries of the rpi4 executable (see `readelf -d boticelli`), and what the
# maintainer scripts and units call.
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "libc6 (>= 2.36), libstdc++6 (>= 12), libgcc-s1, libgpiod2 (>= 1.6), libgpiodcxx1 (>= 1.6), adduser, systemd, iproute2, udev")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${BOTICELLI_PACKAGING_DIR}/postinst ${BOTICELLI_PACKAGING_DIR}/prerm
    ${BOTICELLI_PACKAGING_DIR}/postrm)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
