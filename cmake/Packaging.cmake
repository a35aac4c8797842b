# cmake --install and the .deb (cpack -G DEB): the executables, the systemd unit, the installed
# config in /etc/surroundd/ (a conffile: upgrades keep the integrator's edits), the docs, the
# manual pages, the licence (Apache-2.0) as a machine-readable copyright file and the changelog.
# The binaries are stripped; their debug symbols go into a separate surroundd-dbgsym package. The
# service's state (the LUT cache) lives in systemd's StateDirectory=surroundd, created by systemd.
# tests/packaging/lintian_test.sh builds the package and fails on any lintian error.
include(GNUInstallDirs)
include(${CMAKE_CURRENT_LIST_DIR}/Manuals.cmake)

install(TARGETS surroundd surroundctl surround-synth surround-calibrate surround-bench
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES systemd/surroundd.service DESTINATION lib/systemd/system)
# The installed config shows the live view on a page on this machine; a build without HTTP has
# no page, so its config writes the top view as a picture in the state folder instead (the
# installed config must pass --check-config in every build: tests/packaging/install_test.sh).
if(SURROUNDD_WITH_HTTP)
  set(installed_config config/surroundd.yaml)
else()
  set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS
               ${PROJECT_SOURCE_DIR}/config/surroundd.yaml)
  file(READ ${PROJECT_SOURCE_DIR}/config/surroundd.yaml text)
  set(page "  # The live view and its page (health, frame rate, view buttons), on this machine only; a listen
  # address beyond it serves every network the vehicle computer is on.
  - {type: http, stream: surround, listen: 127.0.0.1:8080}")
  string(FIND "${text}" "${page}" at)
  if(at EQUAL -1)
    message(FATAL_ERROR "config/surroundd.yaml: its http output is not as cmake/Packaging.cmake "
                        "replaces it in a build without HTTP: change both")
  endif()
  string(REPLACE "${page}" "  # This build has no HTTP page: the top view, 5 s after the start.
  - {type: snapshot, stream: surround, view: top, path: /var/lib/surroundd/top.png, at_s: 5}"
         text "${text}")
  set(installed_config ${PROJECT_BINARY_DIR}/surroundd.yaml)
  file(WRITE ${installed_config} "${text}")
endif()
install(FILES ${installed_config} DESTINATION /etc/surroundd)
install(FILES README.md config/surroundd.reference.yaml config/demo.yaml
        DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY config/rigs DESTINATION ${CMAKE_INSTALL_DOCDIR})
# The guide the README links to (docs/*.md and its pictures), where the README's links find it.
install(DIRECTORY docs/ DESTINATION ${CMAKE_INSTALL_DOCDIR}/docs
        FILES_MATCHING PATTERN "*.md" PATTERN "*.png" PATTERN "man" EXCLUDE)
install(FILES cmake/debian/copyright DESTINATION ${CMAKE_INSTALL_DOCDIR})
# A native package's changelog, compressed as Debian policy asks (gzip -9n: reproducible).
set(changelog ${PROJECT_BINARY_DIR}/changelog.gz)
add_custom_command(
  OUTPUT ${changelog}
  COMMAND gzip -9nc ${PROJECT_SOURCE_DIR}/cmake/debian/changelog > ${changelog}
  DEPENDS ${PROJECT_SOURCE_DIR}/cmake/debian/changelog
  COMMENT "changelog.gz")
add_custom_target(changelog ALL DEPENDS ${changelog})
install(FILES ${changelog} DESTINATION ${CMAKE_INSTALL_DOCDIR})

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME surroundd)
set(CPACK_PACKAGE_VENDOR "surroundd")
set(CPACK_PACKAGE_CONTACT "surroundd maintainers <maintainers@surroundd.dev>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "live 360-degree 3D surround view from vehicle cameras")
# The extended description (CPack puts the summary above it as the synopsis).
set(CPACK_DEBIAN_PACKAGE_DESCRIPTION
    "surroundd is a daemon that gives a vehicle a live surround view from four
cameras (V4L2, libcamera, or recorded files replayed as virtual cameras). It
stitches them through a precomputed look-up table onto a spherical panorama,
corrects colour across the seams with Poisson local colour correction,
textures the panorama onto a flat, 360 or bowl mesh around a car model, and
renders it with EGL and OpenGL ES to video files, network streams, a web
page, an X11 window or a DRM/KMS display. It runs as a systemd service
configured by one YAML file, and comes with tools to calibrate the cameras,
to render synthetic recordings with ground truth, and to benchmark it.")
set(CPACK_RESOURCE_FILE_LICENSE ${PROJECT_SOURCE_DIR}/LICENSE)
# The binaries' debug info (RelWithDebInfo) goes into surroundd-dbgsym (a .ddeb, by build ID), and
# the binaries in the package are stripped.
set(CPACK_DEBIAN_DEBUGINFO_PACKAGE ON)
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION video)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)  # the runtime libraries, from what the binaries link
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "libegl-mesa0, libgl1-mesa-dri")  # EGL without a GPU driver
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA ${CMAKE_CURRENT_LIST_DIR}/debian/conffiles)
include(CPack)
