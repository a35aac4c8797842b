#!/bin/sh
# The main job, end to end: installs what is missing, builds (the daemon and every tool the README
# names, in build/release), makes the synthetic sample recording (once; it is cached in
# recordings/demo), and replays it through surroundd to the outputs of config/demo.yaml.
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
# With what `cmake --install build/release` installs besides them: the changelog, and the manual
# pages where help2man made them (cmake/Manuals.cmake), so that installing after the demo works.
manuals=""
if command -v help2man >/dev/null 2>&1; then manuals=manuals; fi
cmake --build --preset release --target surroundd surroundctl surround-synth surround-calibrate \
  surround-bench surround-gpu-check changelog $manuals
# recordings/demo is the demo's own: made again (--force) only when the generator or its arguments
# changed since (a recording of the same key is kept, "up to date").
build/release/tools/synth/surround-synth --rig config/rigs/paper.yaml --out recordings/demo --force
build/release/daemon/surroundd --config config/demo.yaml "$@" &
daemon=$!
# The rear view with its guidelines (issue 21), after the snapshots at 5 s: the car in reverse
# with the wheel turned a turn left, straight and a turn right, each snapshot once the pictures
# show it: six frame sets after the signal (its view rule is applied within one), and no switch of
# view under way (the daemon's status says "view switch: under way" until the new view has
# settled), however long a loaded machine takes.
ctl() { build/release/tools/surroundctl/surroundctl --socket out/demo/control.sock "$@"; }
setsIn() { echo "$1" | sed -n '1s/^\([0-9]*\) frame sets.*/\1/p'; }
# Waits until the daemon has made frame set $1 and no switch of view is under way; 1 when the
# replay ends first.
waitFor() {
  while kill -0 "$daemon" 2>/dev/null; do
    status=$(ctl status 2>/dev/null) || status=""
    sets=$(setsIn "$status")
    if [ "${sets:-0}" -ge "$1" ] && ! echo "$status" | grep -q "view switch: under way"; then
      return 0
    fi
    sleep 0.1
  done
  return 1
}
waitFor 180 || true
for turn in left:360 straight:0 right:-360; do
  name=${turn%%:*}
  sets=$(setsIn "$(ctl status 2>/dev/null)")
  if ctl signal gear=R "steering_deg=${turn#*:}" >/dev/null 2>&1 &&
    waitFor $((${sets:-0} + 6)) && ctl snapshot "out/demo/rear-$name.png" >/dev/null 2>&1; then :; else
    echo "demo: no out/demo/rear-$name.png: the replay ended first"
  fi
done
ctl signal gear=D >/dev/null 2>&1 || true
wait "$daemon"
echo
echo "demo outputs:"
for file in out/demo/*; do echo "  $(pwd)/$file"; done
