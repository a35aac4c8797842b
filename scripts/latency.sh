#!/bin/sh
# Capture-to-output latency at the cameras' own pace: replays a benchmark recording (made by
# scripts/bench.sh) in a loop for SECONDS through surroundd, with a 1280x720 orbit video and an HTTP
# output, then prints `surroundctl status` (frame rate, stage p50/p99, latency p50/p99).
#   scripts/latency.sh [480p|720p|1080p] [SECONDS] [auto|always|never] [decode|yuyv|uyvy|nv12]
# The third argument is capture.latest_wins: `always` shows the replay as a live rig would run it.
# The fourth: decode the files as they play (the default), or preload them into memory as a
# camera's frames of that format (no decodes on the cores, as a live rig).
set -eu
cd "$(dirname "$0")/.."
input=${1:-480p}
seconds=${2:-20}
latest=${3:-auto}
case ${4:-decode} in
  decode) preload= ;;
  yuyv | uyvy | nv12) preload=$4 ;;
  *) echo "$0: the fourth argument is decode, yuyv, uyvy or nv12, not '$4'" >&2; exit 2 ;;
esac
. scripts/replay-rig.sh
cat > "$work/config.yaml" <<CONFIG
rig: {file: rig.yaml}
capture: {pacing: realtime, latest_wins: $latest}
panorama: {width_px: $panorama_width, height_px: $panorama_height}
render: {width_px: 1280, height_px: 720, view: orbit}
control: {socket: $work/control.sock}
outputs:
  - {type: video, stream: surround, path: out/surround.mp4, crf: 20, preset: ultrafast}
  - {type: http, stream: surround, view: top, listen: "127.0.0.1:0"}
CONFIG
build/release/daemon/surroundd --config "$work/config.yaml" > "$work/log.txt" 2>&1 &
pid=$!
sleep "$seconds"
echo "4 x $input${preload:+ preloaded as $preload}, panorama ${panorama_width}x$panorama_height, real time, latest_wins $latest, after $seconds s:"
build/release/tools/surroundctl/surroundctl --socket "$work/control.sock" status
kill -TERM "$pid"
wait "$pid"
