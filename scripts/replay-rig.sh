# shellcheck shell=sh
# shellcheck disable=SC2034 # the variables it sets are for the script that sources it
# Sourced by the scripts that replay a benchmark recording through surroundd at the cameras' own
# pace (latency.sh, view-switch.sh): builds surroundd and surroundctl, checks that
# recordings/bench/$input exists (made by scripts/bench.sh), and writes $work/rig.yaml, the
# recording's rig with every source looping (and preloaded into memory in the pixel format
# $preload names, when the sourcing script sets it: yuyv, uyvy or nv12); sets $recording,
# $panorama_width, $panorama_height and $work (removed on exit).
recording=$PWD/recordings/bench/${input:?}
[ -f "$recording/rig.yaml" ] || { echo "$0: no $recording; run scripts/bench.sh first" >&2; exit 2; }
cmake --preset release >/dev/null
cmake --build --preset release --target surroundd surroundctl >/dev/null
panorama_width=$(sed -n 's/.*panorama_size=\([0-9]*\)x[0-9]*.*/\1/p' "$recording/manifest.yaml")
panorama_height=$(sed -n 's/.*panorama_size=[0-9]*x\([0-9]*\).*/\1/p' "$recording/manifest.yaml")
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
escaped=$(printf '%s' "$recording" | sed 's/[\/&]/\\&/g')
held=${preload:+, preload: true, format: $preload}
sed "s/source: {file: \(.*\)}/source: {file: $escaped\/\1, loop: true$held}/" "$recording/rig.yaml" \
  > "$work/rig.yaml"
