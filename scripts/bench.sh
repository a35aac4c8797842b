#!/bin/sh
# The benchmarks: installs what is missing, builds (release), makes the benchmark recordings (the
# paper rig at 4 x 854x480, 1280x720 and 1920x1080, 2 s each, with ground truth; once, then cached
# in recordings/bench/, replaced when they were made with other arguments) and two with the
# vehicle's body in view, and runs surround-bench stitch, colour and pipeline on them; colour also
# on the shared real rigs (config/real/) when ../shared/data is there. Extra arguments go to each, e.g.
# --threads 1, --repeats 5; --json (first) prints stitch's and pipeline's JSON only.
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release --target surround-synth surround-bench
synth=build/release/tools/synth/surround-synth
# name, camera size, panorama size (about the cameras' angular resolution, capped at 2048 wide)
while read -r name size panorama; do
  "$synth" --rig config/rigs/paper.yaml --out "recordings/bench/$name" --size "$size" \
    --panorama-size "$panorama" --seconds 2 --seed 3 --force
done <<INPUTS
480p 854x480 1024x512
720p 1280x720 1536x768
1080p 1920x1080 2048x1024
INPUTS
# Real-rig colour figures (issue 15): the vehicle's body in view with extreme photometrics, and
# crates and a wall 1-3 m from the seams; 0.2 s each.
"$synth" --rig config/rigs/fisheye-body.yaml --out recordings/bench/body-extreme --size 1280x720 \
  --panorama-size 1536x768 --seconds 0.2 --seed 5 --photometrics extreme --force
"$synth" --rig config/rigs/fisheye-body.yaml --out recordings/bench/body-near-objects \
  --size 1280x720 --panorama-size 1536x768 --seconds 0.2 --seed 3 --scene near-objects --force
# surround-bench stitch, colour and pipeline (colour has no JSON and is left out with --json).
inputs="recordings/bench/480p recordings/bench/720p recordings/bench/1080p"
build/release/tools/bench/surround-bench stitch "$@" $inputs
if [ "${1:-}" != "--json" ]; then
  build/release/tools/bench/surround-bench colour "$@" $inputs recordings/bench/body-extreme \
    recordings/bench/body-near-objects
  # The shared samples (two real vehicles), where ../shared/data is beside the checkout.
  if [ -d ../shared/data ]; then
    build/release/tools/bench/surround-bench colour "$@" config/real/pjlab-fisheye-real.yaml \
      config/real/pjlab-ocam-real.yaml config/real/pjlab-carla-pinhole.yaml
  else
    echo "bench: ../shared/data is absent: the real rigs' colour figures are left out"
  fi
fi
build/release/tools/bench/surround-bench pipeline "$@" $inputs
