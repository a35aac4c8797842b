# cmake --install and the .deb (cpack -G DEB): the executables, the systemd unit, the installed
# config in /etc/surroundd/ (a conffile: upgrades keep the integrator's edits), and the docs. The
# service's state (the LUT cache) lives in systemd's StateDirectory=surroundd, created by systemd.
include(GNUInstallDirs)

install(TARGETS surroundd surroundctl surround-synth surround-calibrate surround-bench
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
install(FILES systemd/surroundd.service DESTINATION lib/systemd/system)
install(FILES config/surroundd.yaml DESTINATION /etc/surroundd)
install(FILES README.md config/surroundd.reference.yaml config/demo.yaml
        DESTINATION ${CMAKE_INSTALL_DOCDIR})
install(DIRECTORY config/rigs DESTINATION ${CMAKE_INSTALL_DOCDIR})

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME surroundd)
set(CPACK_PACKAGE_VENDOR "surroundd")
set(CPACK_PACKAGE_CONTACT "surroundd maintainers <surroundd@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "live 360-degree 3D surround view from four vehicle cameras")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION video)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)  # the runtime libraries, from what the binaries link
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "libegl-mesa0, libgl1-mesa-dri")  # EGL without a GPU driver
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA ${CMAKE_CURRENT_LIST_DIR}/debian/conffiles)
include(CPack)
