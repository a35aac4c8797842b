#!/bin/sh
# The benchmark recordings, made by the surround-synth given as $1: the paper rig at 4 x 854x480,
# 1280x720 and 1920x1080, 2 s each, with ground truth, and two with the vehicle's body in view.
# Made once and kept in recordings/bench/ (surround-synth --force replaces one only when it was
# made with other arguments). Used by scripts/bench.sh and scripts/bench-compare.sh.
set -eu
cd "$(dirname "$0")/.."
synth="$1"
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
# The calibration watch's mount refinement (issue 48; surround-bench mounts): the fisheye rig
# driving over textured ground, a camera knocked 5 s in (yaw, pitch, roll), and ten minutes with
# none knocked (false alarms).
while read -r name turn; do
  "$synth" --rig config/rigs/fisheye-body.yaml --out "recordings/bench/$name" --size 1280x720 \
    --panorama-size 256x128 --seconds 60 --fps 2 --seed 3 --turn "$turn" --force
done <<TURNS
turn-yaw2 back:2,0,0@5
turn-pitch2 front:0,2,0@5
turn-roll3 left:0,0,3@5
TURNS
"$synth" --rig config/rigs/fisheye-body.yaml --out recordings/bench/drive-10min --size 1280x720 \
  --panorama-size 256x128 --seconds 600 --fps 1 --seed 4 --force
