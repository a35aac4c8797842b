# shellcheck shell=sh disable=SC2034 # sourced: its lists are used by the scripts that source it
# Sourced: the Debian 12 packages surroundd needs, written once, for scripts/install-deps.sh (this
# machine) and scripts/cross-arm64.sh (the arm64 sysroot).

# The libraries it is compiled against, on every architecture.
LIBRARY_PACKAGES="
  libopencv-dev libyaml-cpp-dev libspdlog-dev libfmt-dev zlib1g-dev libtinygltf-dev
  libavcodec-dev libavformat-dev libavutil-dev libswscale-dev
  libsuitesparse-dev libeigen3-dev
  libegl-dev libgles-dev
  libx11-dev libxext-dev libdrm-dev libgbm-dev
  libturbojpeg0-dev libcamera-dev libsystemd-dev
  libmicrohttpd-dev
"
# Mesa's EGL and its llvmpipe: rendering without a GPU, here and under qemu.
MESA_PACKAGES="libegl-mesa0 libgl1-mesa-dri"
# The RTSP output: GStreamer's RTSP server, and the plugins it streams through (not in the arm64
# sysroot: the cross build leaves the part out).
RTSP_PACKAGES="libgstrtspserver-1.0-dev gstreamer1.0-plugins-base gstreamer1.0-plugins-good"
# What builds it here.
TOOL_PACKAGES="build-essential cmake ninja-build pkg-config ccache python3"
# GoogleTest, which the tests link (the cross build's too).
GTEST_PACKAGES="libgtest-dev libgmock-dev"
