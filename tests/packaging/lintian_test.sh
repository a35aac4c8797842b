#!/bin/sh
# The .deb as Debian's lintian judges it: `cpack -G DEB` from the build, then lintian on the
# package; any error (E:) fails the test, warnings are printed. Also checks what the package
# holds: stripped binaries (their symbols in the -dbgsym .ddeb), the copyright file, the
# changelog and the five manual pages.
#   lintian_test.sh BUILD_DIR
set -eu
build="$1"
if ! command -v lintian >/dev/null 2>&1; then
  echo "lintian_test: lintian is not installed (Debian: lintian); the package is not checked"
  exit 0
fi
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT
cpack --config "$build/CPackConfig.cmake" -G DEB -B "$out" >"$out/cpack.log" 2>&1 || {
  cat "$out/cpack.log" >&2
  exit 1
}
deb=$(ls "$out"/surroundd_*.deb)
ls "$out"/surroundd-dbgsym_*.ddeb >/dev/null
contents=$(dpkg-deb -c "$deb")
for file in ./usr/share/doc/surroundd/copyright ./usr/share/doc/surroundd/changelog.gz \
    ./usr/share/man/man8/surroundd.8.gz ./usr/share/man/man1/surroundctl.1.gz \
    ./usr/share/man/man1/surround-calibrate.1.gz ./usr/share/man/man1/surround-synth.1.gz \
    ./usr/share/man/man1/surround-bench.1.gz; do
  if ! printf '%s\n' "$contents" | grep -q " $file\$"; then
    echo "lintian_test: the package has no $file" >&2
    exit 1
  fi
done
dpkg-deb -x "$deb" "$out/root"
if file "$out/root/usr/bin/surroundd" | grep -q "not stripped"; then
  echo "lintian_test: /usr/bin/surroundd is not stripped" >&2
  exit 1
fi
lintian --allow-root "$deb" >"$out/lintian.txt" 2>&1 || true
cat "$out/lintian.txt"
if grep -q "^E: " "$out/lintian.txt"; then
  echo "lintian_test: lintian reports errors" >&2
  exit 1
fi
echo "lintian_test: $(basename "$deb") ($(du -k "$deb" | cut -f1) KiB): no lintian errors"
