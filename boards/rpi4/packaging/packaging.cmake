# Packaging of the rpi4 board: install rules and a CPack .deb (arm64 for the rpi4 preset, armhf for armhf).
include(GNUInstallDirs)
set(BOTICELLI_PACKAGING_DIR ${CMAKE_CURRENT_LIST_DIR})

install(TARGETS boticelli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES ${BOTICELLI_PACKAGING_DIR}/boticelli.service
              ${BOTICELLI_PACKAGING_DIR}/boticelli-can0.service
        DESTINATION lib/systemd/system)
install(FILES ${BOTICELLI_PACKAGING_DIR}/60-boticelli.rules DESTINATION lib/udev/rules.d)
# The configuration file, every key commented out at its default: a conffile (listed in
# DEBIAN/conffiles below), so dpkg keeps an administrator's changes across upgrades.
install(FILES ${BOTICELLI_PACKAGING_DIR}/boticelli.conf DESTINATION /etc/boticelli)
install(FILES ${PROJECT_SOURCE_DIR}/docs/flashing.md ${PROJECT_SOURCE_DIR}/docs/console.md
              ${PROJECT_SOURCE_DIR}/docs/configuration.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR} OPTIONAL)
install(FILES ${BOTICELLI_PACKAGING_DIR}/copyright DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${BOTICELLI_PACKAGING_DIR}/boticelli.bash-completion
        DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions RENAME boticelli)

# The changelog and the manual page gzipped as Debian wants them: maximum compression, no
# name or time stamp in the header (gzip -9n), so the package is reproducible.
set(boticelli_gz_dir ${CMAKE_CURRENT_BINARY_DIR}/packaging)
set(boticelli_gz_files)
foreach(pair "changelog;changelog.gz" "boticelli.8;boticelli.8.gz")
  list(GET pair 0 source)
  list(GET pair 1 output)
  add_custom_command(
    OUTPUT ${boticelli_gz_dir}/${output}
    COMMAND ${CMAKE_COMMAND} -E make_directory ${boticelli_gz_dir}
    COMMAND gzip -9nc ${BOTICELLI_PACKAGING_DIR}/${source} > ${boticelli_gz_dir}/${output}
    DEPENDS ${BOTICELLI_PACKAGING_DIR}/${source}
    COMMENT "gzip -9n ${source}" VERBATIM)
  list(APPEND boticelli_gz_files ${boticelli_gz_dir}/${output})
endforeach()
add_custom_target(boticelli_package_docs ALL DEPENDS ${boticelli_gz_files})
install(FILES ${boticelli_gz_dir}/changelog.gz DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${boticelli_gz_dir}/boticelli.8.gz DESTINATION ${CMAKE_INSTALL_MANDIR}/man8)

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
set(CPACK_PACKAGE_CONTACT "Boticelli maintainers <boticelli-maintainers@lists.example.org>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "firmware of the Boticelli exploration robot (Raspberry Pi 4)")
# The extended description (control file lines after the summary).
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "Boticelli explores an unknown room with one camera on a pan-tilt unit and a\n\
two-wheel ODrive base and finds a target without touching anything. It models\n\
the room with a piecewise-linear occupancy function (an Adaptive Logic Network)\n\
fitted to single-camera stereo, after D. O. Gorodnichy's thesis.\n\
.\n\
This package holds the firmware for the Raspberry Pi 4 reference robot as a\n\
hardened systemd service with a software watchdog, the unit that brings up the\n\
CAN interface, udev rules for the GPIO chip, watchdog and camera, the\n\
configuration file /etc/boticelli/boticelli.conf, the manual page and bash\n\
completion. The serial console is documented in\n\
/usr/share/doc/boticelli/console.md.")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${BOTICELLI_DEB_ARCH})
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
# Runtime libraries of the rpi4 executable (see `readelf -d boticelli`; Debian 12 ships
# libgpiodcxx.so.1 in libgpiod2, there is no libgpiodcxx1 package), and what the
# maintainer scripts and units call.
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "libc6 (>= 2.36), libstdc++6 (>= 12), libgcc-s1, libgpiod2 (>= 1.6), libpng16-16 (>= 1.6), libtomlplusplus3 (>= 3.3.0), systemd, init-system-helpers (>= 1.54~), iproute2, udev")
# The console from a laptop or the robot itself, and CAN bring-up checks (docs/flashing.md).
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "picocom, can-utils")
# A stripped binary in the package, its debug information in boticelli-dbgsym (a .ddeb):
# CPack splits it off (objcopy --only-keep-debug, --strip-unneeded, a debug link), with the
# target's binutils (CPACK_STRIP_FILES would strip before the split and lose it).
set(CPACK_DEBIAN_DEBUGINFO_PACKAGE ON)
set(CPACK_OBJCOPY_EXECUTABLE ${CMAKE_OBJCOPY})
set(CPACK_READELF_EXECUTABLE ${CMAKE_READELF})
# preinst creates the service user and the group gpio before the udev rule is unpacked.
set(CPACK_DEBIAN_PACKAGE_PREDEPENDS "adduser")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    ${BOTICELLI_PACKAGING_DIR}/preinst ${BOTICELLI_PACKAGING_DIR}/postinst ${BOTICELLI_PACKAGING_DIR}/prerm
    ${BOTICELLI_PACKAGING_DIR}/postrm ${BOTICELLI_PACKAGING_DIR}/conffiles)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
include(CPack)
