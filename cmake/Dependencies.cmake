# All dependencies come from Debian 12's packages (scripts/install-deps.sh installs them).
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)
find_package(OpenCV 4.5 REQUIRED COMPONENTS core imgproc imgcodecs calib3d aruco)
find_package(yaml-cpp REQUIRED)
find_package(spdlog REQUIRED)
find_package(fmt REQUIRED)
find_package(ZLIB REQUIRED)
# Eigen (libeigen3-dev, headers only): the rig's rotations from mount angles and quaternions.
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
pkg_check_modules(FFMPEG REQUIRED IMPORTED_TARGET libavformat libavcodec libavutil libswscale)
pkg_check_modules(SYSTEMD REQUIRED IMPORTED_TARGET libsystemd)  # sd_notify: readiness, watchdog
# tinygltf (libtinygltf-dev, a shared library in Debian): the car's own glTF model.
pkg_check_modules(TINYGLTF REQUIRED IMPORTED_TARGET tinygltf)

# SuiteSparse CHOLMOD (libsuitesparse-dev). SuiteSparse 7 installs a CMake config with this
# target; Debian 12's 5.12 has neither that nor a pkg-config file, so look for it directly.
find_package(CHOLMOD CONFIG QUIET)
if(NOT TARGET SuiteSparse::CHOLMOD)
  find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
  find_library(CHOLMOD_LIBRARY cholmod REQUIRED)
  # cholmod.h includes SuiteSparse_config.h, whose symbols (the allocator hooks) live here.
  find_library(SUITESPARSE_CONFIG_LIBRARY suitesparseconfig REQUIRED)
  add_library(SuiteSparse::CHOLMOD UNKNOWN IMPORTED)
  set_target_properties(SuiteSparse::CHOLMOD PROPERTIES
    IMPORTED_LOCATION "${CHOLMOD_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${CHOLMOD_INCLUDE_DIR}"
    INTERFACE_LINK_LIBRARIES "${SUITESPARSE_CONFIG_LIBRARY}")
endif()
