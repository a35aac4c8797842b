#!/bin/sh
# The installed product: `cmake --install` into a staging root puts the executables, the systemd
# unit, the config and the docs where the .deb does; the installed config passes
# `surroundd --check-config`; and `systemd-analyze verify` accepts the unit (its ExecStart pointed
# at the staged binary, since nothing is installed on this machine).
set -eu
build="$1"
stage="$(mktemp -d)"
trap 'rm -rf "$stage"' EXIT
DESTDIR="$stage/root" cmake --install "$build" --prefix /usr >/dev/null
for file in usr/bin/surroundd usr/bin/surround-synth usr/bin/surround-calibrate \
    usr/bin/surround-bench usr/lib/systemd/system/surroundd.service \
    etc/surroundd/surroundd.yaml usr/share/doc/surroundd/surroundd.reference.yaml; do
  if [ ! -e "$stage/root/$file" ]; then
    echo "install_test: /$file is not installed" >&2
    exit 1
  fi
done
# The file must be good; its cameras (`device: auto`) are this machine's, so where it has none (a
# build machine) the check says exactly that, and nothing else.
status=0
check=$("$stage/root/usr/bin/surroundd" --check-config \
  --config "$stage/root/etc/surroundd/surroundd.yaml" 2>&1) || status=$?
echo "$check"
case "$status:$check" in
  0:*": good ("*) ;;
  2:*"the file is good ("*"cannot be opened here"*)
    if echo "$check" | grep -v "^surroundd: camera '[a-z]*': " | grep -v "the file is good (" | grep -q .; then
      echo "install_test: the installed config's check says more than that its cameras are missing" >&2
      exit 1
    fi ;;
  *)
    echo "install_test: the installed config does not pass --check-config (exit $status)" >&2
    exit 1 ;;
esac
if ! command -v systemd-analyze >/dev/null 2>&1; then
  echo "install_test: no systemd-analyze; the unit is not verified"
  exit 0
fi
mkdir "$stage/unit"
sed -e "s|/usr/bin/surroundd|$stage/root/usr/bin/surroundd|" \
    -e "s|/etc/surroundd/surroundd.yaml|$stage/root/etc/surroundd/surroundd.yaml|" \
    "$stage/root/usr/lib/systemd/system/surroundd.service" >"$stage/unit/surroundd.service"
systemd-analyze verify "$stage/unit/surroundd.service"
echo "install_test: installed files, config and unit are good"
