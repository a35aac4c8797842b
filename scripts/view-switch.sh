#!/bin/sh
# Time from a vehicle signal to its view on screen (issue 21): replays a benchmark recording (made
# by scripts/bench.sh) in a loop at its own pace, with a 1280x720 video of the orbit view and the
# view rule gear R -> top, then sends `surroundctl signal gear=R` and `gear=D` in turn, ROUNDS times
# each, and prints each switch's time from the signal to its first picture and to the new view
# settled (over render.transition_s: 0.4 s unless TRANSITION_S says otherwise), as surroundd's
# status gives it, then their spread.
#   scripts/view-switch.sh [480p|720p|1080p] [ROUNDS] [TRANSITION_S]
set -eu
cd "$(dirname "$0")/.."
input=${1:-720p}
rounds=${2:-5}
transition=${3:-0.4}
. scripts/replay-rig.sh
cat > "$work/config.yaml" <<CONFIG
rig: {file: rig.yaml}
capture: {pacing: realtime}
panorama: {width_px: $panorama_width, height_px: $panorama_height}
render: {width_px: 1280, height_px: 720, view: orbit, transition_s: $transition}
control: {socket: $work/control.sock}
vehicle_signals:
  stale_after_s: 30
  view_rules: [{gear: R, view: top}]
outputs:
  - {type: video, stream: surround, path: out/surround.mp4, crf: 20, preset: ultrafast}
CONFIG
ctl() { build/release/tools/surroundctl/surroundctl --socket "$work/control.sock" "$@"; }
build/release/daemon/surroundd --config "$work/config.yaml" > "$work/log.txt" 2>&1 &
pid=$!
sleep 3
echo "4 x $input, panorama ${panorama_width}x$panorama_height, real time, 1280x720 video, orbit <-> top by gear R / D, transition $transition s:"
round=1
while [ "$round" -le "$rounds" ]; do
  for gear in R D; do
    ctl signal gear=$gear >/dev/null
    sleep 1.5
    printf 'gear %s: ' "$gear"
    ctl status | sed -n 's/^view switch: //p'
  done
  round=$((round + 1))
done
ctl status | sed -n 's/^frame rate: /frame rate: /p'
kill -TERM "$pid"
wait "$pid"
echo "settled after the signal (s):"
sed -n 's/.*view switch: first picture [0-9.]* s, settled \([0-9.]*\) s.*/\1/p' "$work/log.txt" |
  sort -n | awk '{ v[NR] = $1 } END { if (NR) printf "  min %.2f  median %.2f  max %.2f (%d switches)\n", v[1], v[int((NR + 1) / 2)], v[NR], NR }'
