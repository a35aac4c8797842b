#!/bin/sh
# ctest: surround-synth lays a calibration mat around the fisheye rig and takes one picture per
# camera (with the true rig.yaml and nominal-rig.yaml, each mount a few cm and degrees off, as
# measured by hand); surround-calibrate guide --mat solves every mount on its page, starting from
# a copy of the nominal rig; tests/browser/mat_guide.test.mjs follows the page in headless
# Chromium to the verdict and checks that the mounts written into the rig are the true ones.
# Then the same pictures against the mat declared with 25 cm squares instead of 20: the page
# must fail, say that nothing was written, and the rig must stay as it was.
#   mat_guide_test.sh SURROUND_SYNTH SURROUND_CALIBRATE SOURCE_DIR
set -eu
synth=$1
calibrate=$2
source_dir=$3
here=$(cd "$(dirname "$0")" && pwd)

. "$here/test_setup.sh"
"$synth" --rig "$source_dir/config/rigs/fisheye.yaml" --calibration-mat 7x6@0.2 --size 960x540 \
  --out "$work/mat" > "$work/synth.txt"
sed 's/square_m: 0.2$/square_m: 0.25/' "$work/mat/mat.yaml" > "$work/wrong-mat.yaml"
. "$here/served_url.sh"

# guide_on MAT RIG LOG [--expect-refusal]: serves the guide on MAT from a copy of the nominal rig
# at RIG, follows its page, stops it; the status of the check (the guide's exit status must be
# 0 after a pass, 1 after a refusal).
guide_on() {
  cp "$work/mat/nominal-rig.yaml" "$2"
  "$calibrate" guide --mat "$1" --rig "$2" --images "$work/mat" --listen 127.0.0.1:0 > "$3" 2>&1 &
  pid=$!
  url=$(served_url "$3" "$pid" 's/^guide page: \(http:[^ ]*\).*/\1/p')
  if [ -z "$url" ]; then
    echo "mat_guide_test: surround-calibrate guide --mat did not serve its page:" >&2
    cat "$3" >&2
    return 1
  fi
  result=0
  node "$here/mat_guide.test.mjs" "$url" "$2" "$work/mat/rig.yaml" "$work/mat/nominal-rig.yaml" \
    ${4:-} || result=$?
  guide=0
  kill "$pid" && wait "$pid" || guide=$?
  pid=""
  expected=0
  [ -n "${4:-}" ] && expected=1
  if [ "$guide" -ne "$expected" ]; then
    echo "mat_guide_test: surround-calibrate guide --mat exited $guide, expected $expected" >&2
    result=1
  fi
  cat "$3"
  return $result
}

status=0
guide_on "$work/mat/mat.yaml" "$work/rig.yaml" "$work/log.txt" || status=1
grep -q 'square_m: 0.25' "$work/wrong-mat.yaml" || { echo "mat_guide_test: no square_m to change" >&2; exit 1; }
guide_on "$work/wrong-mat.yaml" "$work/rig-refused.yaml" "$work/log-refused.txt" --expect-refusal || status=1
exit $status
