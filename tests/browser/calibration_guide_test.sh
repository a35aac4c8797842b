#!/bin/sh
# ctest: surround-synth writes a generated calibration session (a chessboard walked around a
# fisheye's field), surround-calibrate guide replays it on its page, and
# tests/browser/calibration_guide.test.mjs follows the page in headless Chromium to the pass.
#   calibration_guide_test.sh SURROUND_SYNTH SURROUND_CALIBRATE SOURCE_DIR
set -eu
synth=$1
calibrate=$2
source_dir=$3
here=$(cd "$(dirname "$0")" && pwd)

. "$here/test_setup.sh"
"$synth" --rig "$source_dir/config/rigs/fisheye.yaml" --calibration-session front --size 640x360 \
  --seconds 15 --fps 4 --out "$work/session" > "$work/synth.txt"
"$calibrate" guide --file "$work/session/frame_%04d.png" --fps 4 --board 9x6 --model fisheye \
  --out "$work/lens.yaml" --listen 127.0.0.1:0 > "$work/log.txt" 2>&1 &
pid=$!

# The port it chose is in its first line.
. "$here/served_url.sh"
url=$(served_url "$work/log.txt" "$pid" 's/^guide page: \(http:[^ ]*\).*/\1/p')
if [ -z "$url" ]; then
  echo "calibration_guide_test: surround-calibrate guide did not serve its page:" >&2
  cat "$work/log.txt" >&2
  exit 1
fi
status=0
node "$here/calibration_guide.test.mjs" "$url" "$work/lens.yaml" "$work/session/rig.yaml" || status=$?
kill "$pid" && wait "$pid" || status=$((status == 0 ? 1 : status))
pid=""
cat "$work/log.txt"
exit $status
