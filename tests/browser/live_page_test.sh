#!/bin/sh
# ctest: surroundd serves the surround view of the small synthetic recording (replayed in a loop)
# over HTTP, and tests/browser/live_page.test.mjs checks its page in headless Chromium.
#   live_page_test.sh SURROUNDD FIXTURE_DIR
set -eu
surroundd=$1
recording=$2/synth_small
here=$(cd "$(dirname "$0")" && pwd)

. "$here/test_setup.sh"
# The recording's rig with every source looping, so the page has pictures for as long as it needs.
sed 's/source: {file: \(.*\)}/source: {file: '"$(printf '%s' "$recording" | sed 's/[\/&]/\\&/g')"'\/\1, loop: true}/' \
  "$recording/rig.yaml" > "$work/rig.yaml"
cat > "$work/config.yaml" <<CONFIG
rig: {file: rig.yaml}
pipeline: {threads: 2}
panorama: {width_px: 512, height_px: 256, cache_dir: lut-cache}
render: {width_px: 320, height_px: 240, view: orbit}
outputs:
  - {type: http, stream: surround, listen: "127.0.0.1:0"}
CONFIG
"$surroundd" --config "$work/config.yaml" > "$work/log.txt" 2>&1 &
pid=$!

# The port it chose is in its log.
. "$here/served_url.sh"
url=$(served_url "$work/log.txt" "$pid" 's/.*HTTP stream: \(http:[^ ]*\).*/\1/p')
if [ -z "$url" ]; then
  echo "live_page_test: surroundd did not start its HTTP stream:" >&2
  cat "$work/log.txt" >&2
  exit 1
fi
node "$here/live_page.test.mjs" "$url" --view top
