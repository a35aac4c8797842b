#!/bin/sh
# The benchmarks: installs what is missing, builds (release), makes the benchmark recordings (the
# paper rig at 4 x 854x480, 1280x720 and 1920x1080, 2 s each, with ground truth; once, then cached
# in recordings/bench/, replaced when they were made with other arguments) and two with the
# vehicle's body in view, and runs surround-bench stitch, colour and pipeline on them (and mounts
# on drives with a camera knocked, and ten minutes with none); colour also
# on the shared real rigs (config/real/) when ../shared/data is there. Extra arguments go to each, e.g.
# --threads 1, --repeats 5; --json (first) prints stitch's and pipeline's JSON only.
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release --target surround-synth surround-bench
scripts/bench-recordings.sh build/release/tools/synth/surround-synth
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
if [ "${1:-}" != "--json" ]; then
  build/release/tools/bench/surround-bench mounts recordings/bench/turn-yaw2 \
    recordings/bench/turn-pitch2 recordings/bench/turn-roll3 recordings/bench/drive-10min
fi
