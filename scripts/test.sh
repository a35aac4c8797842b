#!/bin/sh
# Installs what is missing, builds everything with warnings as errors, and runs the whole test suite.
# --minimal: then also builds the `minimal` preset (every optional part left out: X11, DRM, HTTP,
# libcamera) and runs the tests that apply to it; those of left-out parts are not run (configure
# lists them).
set -eu
cd "$(dirname "$0")/.."
minimal=false
for argument in "$@"; do
  case "$argument" in
    --minimal) minimal=true ;;
    *) echo "usage: scripts/test.sh [--minimal]" >&2; exit 2 ;;
  esac
done
scripts/install-deps.sh
cmake --preset ci
cmake --build --preset ci
# The browser test's driver (playwright-core, from the npm registry; it drives Debian's chromium).
npm ci --prefix tests/browser --no-audit --no-fund --loglevel=error
ctest --preset ci -j2
if $minimal; then
  cmake --preset minimal
  cmake --build --preset minimal
  # The package is the full build's concern (tested above).
  ctest --preset minimal -j2 --label-exclude packaging
fi
