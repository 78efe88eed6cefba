# One Debian package: `cpack -G DEB` in a build folder makes
# camhead_VERSION_ARCH.deb with camhead, the modules this build made
# (libcamera, the marker tracker), the service unit and its user, the
# boards, scenes and lens profiles, and the dependencies dpkg-shlibdeps
# finds in them (tests/package/deb_package.sh checks it).
include(GNUInstallDirs)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(FILES ${PROJECT_SOURCE_DIR}/packaging/debian/copyright DESTINATION ${CMAKE_INSTALL_DOCDIR})
# A native package's changelog, compressed as Debian's policy asks
# (gzip -9n: no name or time in the header, so the build is reproducible).
set(camhead_changelog_gz ${PROJECT_BINARY_DIR}/packaging/changelog.gz)
add_custom_command(OUTPUT ${camhead_changelog_gz}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/packaging
  COMMAND gzip -9n -c ${PROJECT_SOURCE_DIR}/packaging/debian/changelog > ${camhead_changelog_gz}
  DEPENDS ${PROJECT_SOURCE_DIR}/packaging/debian/changelog VERBATIM)
add_custom_target(camhead_changelog ALL DEPENDS ${camhead_changelog_gz})
install(FILES ${camhead_changelog_gz} DESTINATION ${CMAKE_INSTALL_DOCDIR})
# camhead links libpng and zlib statically (base/, renderer/), so that
# `camhead render` and `camhead bench` need nothing but a Vulkan driver and
# the C++ runtime; lintian is told so.
install(FILES ${PROJECT_SOURCE_DIR}/packaging/debian/lintian-overrides
  DESTINATION ${CMAKE_INSTALL_DATADIR}/lintian/overrides RENAME camhead)

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME camhead)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
# The address the package names until the project has a list of its own
# (example.org: reserved for examples, RFC 2606).
set(CAMHEAD_PACKAGE_MAINTAINER "camhead developers <camhead@example.org>"
  CACHE STRING "The Debian package's Maintainer field")
set(CPACK_PACKAGE_CONTACT ${CAMHEAD_PACKAGE_MAINTAINER})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "AR camera head: virtual objects with the real lens's blur")
# The synopsis is the summary above; this is the rest, one string.
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
  "camhead reads live camera frames and the lens's focus, iris and zoom
encoders, and composites virtual objects into each frame with the depth of
field the real lens gives the real scene, by Vulkan ray tracing (on a GPU,
or the CPU through Mesa's lavapipe). Output goes to HDMI and to a V4L2
loopback webcam. Runs as the systemd service camhead@BOARD.")
set(CPACK_DEBIAN_PACKAGE_SECTION video)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
# Not linked, but needed: a Vulkan driver (lavapipe where there is no GPU),
# systemd-sysusers for the service's user, and libjpeg-turbo, which the V4L2
# camera opens at run time to decode a webcam's MJPEG (hal/jpeg).
set(CPACK_DEBIAN_PACKAGE_DEPENDS "mesa-vulkan-drivers | vulkan-icd, systemd, libturbojpeg0")
# The boards in /etc/camhead/board are conffiles (pipeline/CMakeLists.txt):
# dpkg keeps an administrator's edits through upgrades and asks before
# replacing one.
list(JOIN CAMHEAD_CONFFILES "\n" camhead_conffiles_text)
file(WRITE ${PROJECT_BINARY_DIR}/packaging/conffiles "${camhead_conffiles_text}\n")
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
  ${PROJECT_SOURCE_DIR}/packaging/debian/postinst ${PROJECT_SOURCE_DIR}/packaging/debian/postrm
  ${PROJECT_BINARY_DIR}/packaging/conffiles)
# One package of every component, the conffiles included (installed only
# with --component conffiles by `cmake --install`).
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_GROUPING ALL_COMPONENTS_IN_ONE)
set(CPACK_COMPONENTS_ALL Unspecified conffiles)
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION TRUE)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_STRIP_FILES TRUE)
include(CPack)
