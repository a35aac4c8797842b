#!/bin/sh
# Capture-to-output latency at the cameras' own pace: replays a benchmark recording (made by
# scripts/bench.sh) in a loop for SECONDS through surroundd, with a 1280x720 orbit video and an HTTP
# output, then prints `surroundctl status` (frame rate, stage p50/p99, latency p50/p99).
#   scripts/latency.sh [480p|720p|1080p] [SECONDS] [auto|always|never]
# The third argument is capture.latest_wins: `always` shows the replay as a live rig would run it.
set -eu
cd "$(dirname "$0")/.."
input=${1:-480p}
seconds=${2:-20}
latest=${3:-auto}
recording=$PWD/recordings/bench/$input
[ -f "$recording/rig.yaml" ] || { echo "latency: no $recording; run scripts/bench.sh first" >&2; exit 2; }
cmake --preset release >/dev/null
cmake --build --preset release --target surroundd surroundctl >/dev/null
panorama=$(sed -n 's/.*panorama_size=\([0-9]*\)x\([0-9]*\).*/\1 \2/p' "$recording/manifest.yaml")
set -- $panorama
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The recording's rig with every source looping.
escaped=$(printf '%s' "$recording" | sed 's/[\/&]/\\&/g')
sed "s/source: {file: \(.*\)}/source: {file: $escaped\/\1, loop: true}/" "$recording/rig.yaml" \
  > "$work/rig.yaml"
cat > "$work/config.yaml" <<CONFIG
rig: {file: rig.yaml}
capture: {pacing: realtime, latest_wins: $latest}
panorama: {width_px: $1, height_px: $2}
render: {width_px: 1280, height_px: 720, view: orbit}
control: {socket: $work/control.sock}
outputs:
  - {type: video, stream: surround, path: out/surround.mp4, crf: 20, preset: ultrafast}
  - {type: http, stream: surround, view: top, listen: "127.0.0.1:0"}
CONFIG
build/release/daemon/surroundd --config "$work/config.yaml" > "$work/log.txt" 2>&1 &
pid=$!
sleep "$seconds"
echo "4 x $input, panorama $1x$2, real time, latest_wins $latest, after $seconds s:"
build/release/tools/surroundctl/surroundctl --socket "$work/control.sock" status
kill -TERM "$pid"
wait "$pid"
