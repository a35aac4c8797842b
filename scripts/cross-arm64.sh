#!/bin/sh
# Builds surroundd for arm64 with Debian's aarch64 cross compiler and runs the tests that need no
# GPU or device under qemu-user: `scripts/cross-arm64.sh`. Not part of scripts/test.sh (about
# an hour on 2 cores); build/arm64/ keeps the build, build/arm64-sysroot/ the sysroot.
#
# The sysroot holds Debian 12's arm64 packages of every library the project uses, and Mesa's
# llvmpipe for the tests that render (EGL without a GPU), unpacked by mmdebstrap (no maintainer
# scripts run, nothing installed on this machine: the amd64 and arm64 -dev packages of OpenCV
# cannot be installed side by side). It is made again when the package list below changes.
# ARM64_JOBS (default 2): compile jobs and tests at once.
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh --cross-arm64
# shellcheck source=scripts/packages.sh
. scripts/packages.sh

sysroot="$PWD/build/arm64-sysroot"
# shellcheck disable=SC2086 # the lists are meant to split into words
packages=$(echo libc6-dev libstdc++-12-dev $LIBRARY_PACKAGES $GTEST_PACKAGES $MESA_PACKAGES | tr ' ' ',')
stamp="$sysroot/.surroundd-packages"

started=$(date +%s)
if [ ! -f "$stamp" ] || [ "$(cat "$stamp")" != "$packages" ]; then
  echo "cross-arm64: making the arm64 sysroot in $sysroot"
  rm -rf "$sysroot"
  mmdebstrap --quiet --variant=extract --architectures=arm64 --include="$packages" \
    bookworm "$sysroot" http://deb.debian.org/debian
  # The linker follows symlinks on this machine: one that names an absolute path would leave the
  # sysroot, so each is made relative to where it lies.
  find "$sysroot" -type l -lname '/*' | while read -r link; do
    target=$(readlink "$link")
    ln -sfn "$(realpath -m --relative-to="$(dirname "$link")" "$sysroot$target")" "$link"
  done
  # What the packages' maintainer scripts would have made: the BLAS and LAPACK that OpenCV and
  # CHOLMOD link are chosen through update-alternatives; the reference ones are in the sysroot.
  for lib in blas lapack; do
    ln -sfn "$lib/lib$lib.so.3" "$sysroot/usr/lib/aarch64-linux-gnu/lib$lib.so.3"
  done
  echo "$packages" >"$stamp"
fi
sysroot_done=$(date +%s)

cmake --preset arm64
cmake --build --preset arm64 -j"${ARM64_JOBS:-2}"
built=$(date +%s)

# Not under emulation: the labels listed in tests/cross-arm64-excluded-labels, each with its reason
# there (one a line; '#' starts a comment).
excluded=$(sed -e 's/#.*//' -e 's/[[:space:]]//g' tests/cross-arm64-excluded-labels |
  grep -v '^$' | paste -sd '|')
status=0
ctest --preset arm64 -j"${ARM64_JOBS:-2}" -LE "^($excluded)\$" || status=$?
finished=$(date +%s)
echo "cross-arm64: sysroot $((sysroot_done - started)) s, build $((built - sysroot_done)) s," \
  "tests under qemu-aarch64 $((finished - built)) s"
exit $status
