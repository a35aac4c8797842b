#!/bin/sh
# Installs what is missing, builds everything with warnings as errors, and runs the whole test suite.
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset ci
cmake --build --preset ci
# The browser test's driver (playwright-core, from the npm registry; it drives Debian's chromium).
npm ci --prefix tests/browser --no-audit --no-fund --loglevel=error
ctest --preset ci -j2
