# The optional parts of surroundd, each a CMake option that defaults to ON where its packages are
# found: an embedded build carries only what its board has. A config that names a part left out
# is refused when it is loaded, with the option and packages that build it in.
#
# surroundd_optional_part(<PART> <what it is> PACKAGES <Debian packages> MODULES <pkg-config modules>)
# sets SURROUNDD_WITH_<PART> (an option) and, when ON, the imported target PkgConfig::<PART>.
set(SURROUNDD_PARTS_IN "")
set(SURROUNDD_PARTS_OUT "")
set(SURROUNDD_PARTS_PACKAGES "")  # "<PART> <packages>" per part, for howToBuildIn()

macro(surroundd_optional_part part what)
  cmake_parse_arguments(PART_ARG "" "" "PACKAGES;MODULES" ${ARGN})
  pkg_check_modules(${part} QUIET IMPORTED_TARGET ${PART_ARG_MODULES})
  list(JOIN PART_ARG_PACKAGES " " part_packages)
  list(JOIN PART_ARG_MODULES " " part_modules)
  option(SURROUNDD_WITH_${part} "${what} (${part_packages})" ${${part}_FOUND})
  if(SURROUNDD_WITH_${part} AND NOT ${part}_FOUND)
    message(FATAL_ERROR "SURROUNDD_WITH_${part} is ON but ${part_modules} was not found: "
                        "install ${part_packages}, or configure with -DSURROUNDD_WITH_${part}=OFF")
  endif()
  # One list item per part: no semicolons inside.
  list(APPEND SURROUNDD_PARTS_PACKAGES "${part} ${part_packages}")
  if(SURROUNDD_WITH_${part})
    list(APPEND SURROUNDD_PARTS_IN "${part}: ${what}")
  else()
    list(APPEND SURROUNDD_PARTS_OUT
         "${part}: ${what} (-DSURROUNDD_WITH_${part}=ON, needs ${part_packages})")
  endif()
endmacro()

surroundd_optional_part(X11 "X11 window output"
  PACKAGES libx11-dev libxext-dev MODULES x11 xext)
surroundd_optional_part(DRM "DRM/KMS display output"
  PACKAGES libdrm-dev libgbm-dev MODULES libdrm gbm)
surroundd_optional_part(HTTP "MJPEG over HTTP output and its live page, surround-calibrate guide"
  PACKAGES libmicrohttpd-dev libturbojpeg0-dev MODULES libmicrohttpd libturbojpeg)
surroundd_optional_part(RTSP "RTSP server output"
  PACKAGES libgstrtspserver-1.0-dev MODULES gstreamer-rtsp-server-1.0 gstreamer-app-1.0)
surroundd_optional_part(LIBCAMERA "libcamera cameras"
  PACKAGES libcamera-dev MODULES libcamera)

# What is in and what is out, once per configure.
function(surroundd_report_parts)
  foreach(part IN LISTS SURROUNDD_PARTS_IN)
    message(STATUS "surroundd: with    ${part}")
  endforeach()
  foreach(part IN LISTS SURROUNDD_PARTS_OUT)
    message(STATUS "surroundd: WITHOUT ${part}")
  endforeach()
endfunction()
