#!/bin/sh
# The main job, end to end: installs what is missing, builds (the daemon and every tool the README
# names, in build/release), makes the synthetic sample recording (once; it is cached in
# recordings/demo), and replays it through surroundd to the outputs of config/demo.yaml.
set -eu
cd "$(dirname "$0")/.."
scripts/install-deps.sh
cmake --preset release
cmake --build --preset release --target surroundd surroundctl surround-synth surround-calibrate \
  surround-bench
build/release/tools/synth/surround-synth --rig config/rigs/paper.yaml --out recordings/demo
build/release/daemon/surroundd --config config/demo.yaml "$@"
echo
echo "demo outputs:"
for file in out/demo/*; do echo "  $(pwd)/$file"; done
