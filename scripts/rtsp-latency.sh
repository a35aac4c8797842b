#!/bin/sh
# Capture to a player's picture over RTSP on this machine: replays a benchmark recording (made by
# scripts/bench.sh) in a loop at the cameras' own pace, as a live rig runs (the newest set wins),
# through surroundd with an rtsp output (1280x720 orbit view, H.264), watches it for SECONDS with
# `surround-bench receive` (FFmpeg, as a player: from each picture's capture time to its decoded
# picture), then prints surroundd's own figures (capture to the picture handed to the output).
#   scripts/rtsp-latency.sh [480p|720p|1080p] [SECONDS] [udp|tcp]
set -eu
cd "$(dirname "$0")/.."
input=${1:-720p}
seconds=${2:-20}
transport=${3:-udp}
. scripts/replay-rig.sh
cmake --build --preset release --target surround-bench >/dev/null
cat > "$work/config.yaml" <<CONFIG
rig: {file: rig.yaml}
capture: {pacing: realtime, latest_wins: always}
panorama: {width_px: $panorama_width, height_px: $panorama_height}
render: {width_px: 1280, height_px: 720, view: orbit}
control: {socket: $work/control.sock}
outputs:
  - {type: rtsp, stream: surround, listen: "127.0.0.1:0", preset: ultrafast}
CONFIG
build/release/daemon/surroundd --config "$work/config.yaml" > "$work/log.txt" 2>&1 &
pid=$!
url=""
for _ in $(seq 600); do
  url=$(sed -n 's/.*RTSP stream: \(rtsp:[^ ]*\).*/\1/p' "$work/log.txt")
  [ -n "$url" ] && break
  kill -0 "$pid" 2>/dev/null || { cat "$work/log.txt"; exit 1; }
  sleep 0.1
done
[ -n "$url" ] || { echo "$0: surroundd never served RTSP" >&2; kill -TERM "$pid"; exit 1; }
echo "4 x $input, panorama ${panorama_width}x$panorama_height, live pace; the player:"
build/release/tools/bench/surround-bench receive --seconds "$seconds" --transport "$transport" "$url"
echo "surroundd:"
build/release/tools/surroundctl/surroundctl --socket "$work/control.sock" status |
  grep -E "frame rate|latency|output"
kill -TERM "$pid"
wait "$pid"
