#!/bin/sh
# Installs the Debian 12 packages surroundd needs to build and run (what scripts/demo.sh needs).
# Idempotent: installs only what is missing and says what that is. Runs apt-get as root, or
# through sudo.
# --tests: also what the test suite needs (GoogleTest, Xvfb, lintian and help2man for the package,
#   OpenCV's sample pictures, Chromium and Node.js for the browser tests): scripts/test.sh.
# --fuzz: also clang and its sanitizer runtimes, for scripts/fuzz.sh (libFuzzer).
# --soak: also gnuplot, for scripts/soak.sh's plot.
# --cross-arm64: also the aarch64 cross compiler, qemu-user and mmdebstrap, for
#   scripts/cross-arm64.sh.
# --device-vm: also QEMU, busybox, kmod and cpio, for scripts/device-vm.sh (the tests' machine with
#   a KMS screen, V4L2 cameras and a CAN bus).
set -eu
# shellcheck source=scripts/packages.sh
. "$(dirname "$0")/packages.sh"

PACKAGES="$TOOL_PACKAGES $LIBRARY_PACKAGES $MESA_PACKAGES $RTSP_PACKAGES"
TEST_PACKAGES="$GTEST_PACKAGES xvfb opencv-doc help2man lintian chromium"
tests=no

for argument in "$@"; do
  case "$argument" in
    --tests) tests=yes; PACKAGES="$PACKAGES $TEST_PACKAGES" ;;
    --fuzz) PACKAGES="$PACKAGES clang libclang-rt-dev" ;;
    --soak) PACKAGES="$PACKAGES gnuplot-nox" ;;
    --cross-arm64) PACKAGES="$PACKAGES crossbuild-essential-arm64 qemu-user-static mmdebstrap" ;;
    --device-vm) PACKAGES="$PACKAGES qemu-system-x86 busybox-static kmod cpio" ;;
    *) echo "usage: scripts/install-deps.sh [--tests] [--fuzz] [--soak] [--cross-arm64] [--device-vm]" >&2; exit 2 ;;
  esac
done

# Node.js drives the browser test; Debian's is enough where none is installed.
if [ "$tests" = yes ] && { ! command -v node >/dev/null 2>&1 || ! command -v npm >/dev/null 2>&1; }; then
  PACKAGES="$PACKAGES nodejs npm"
fi

missing=""
for package in $PACKAGES; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing="$missing $package"
  fi
done

if [ -z "$missing" ]; then
  echo "install-deps: all packages present"
  exit 0
fi

if [ "$(id -u)" -eq 0 ]; then
  as_root=""
elif command -v sudo >/dev/null 2>&1; then
  as_root="sudo"
else
  echo "install-deps: need root or sudo to install:$missing" >&2
  exit 1
fi

echo "install-deps: installing:$missing"
export DEBIAN_FRONTEND=noninteractive
$as_root apt-get update -q
# shellcheck disable=SC2086 # the list is meant to split into words
$as_root apt-get install -y -q --no-install-recommends $missing
