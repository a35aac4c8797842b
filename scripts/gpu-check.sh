#!/bin/sh
# The GPU path (issue 20) measured where there is a GPU: surround-gpu-check on the benchmark rig
# at 4 x 854x480, 1280x720 and 1920x1080, orbit and top views at 1280x720.
#
#   scripts/gpu-check.sh prepare   here: builds surround-gpu-check, makes the kits (each size's
#                                  panorama LUT and first frame set as raw YUYV) and packs them
#                                  with the program and every library it needs into .gpu-kit/
#                                  (about 40 MiB; it needs none of Debian's packages there)
#   scripts/gpu-check.sh run       anywhere: unpacks .gpu-kit/ and runs the check; the report is
#                                  also written to $OUT/gpu-check.txt (or .gpu-kit/gpu-check.txt)
#
# On the device machine (the `device` tool), carry .gpu-kit and .gl (the EGL/GLES loaders, see
# the tool's README) and run `scripts/gpu-check.sh run`: it unpacks .gl's packages first and
# points EGL at NVIDIA's driver. Here it runs on llvmpipe, as a check of the script itself.
# GPU_CHECK_FRAMES sets the frame sets timed per figure (default 300).
set -eu
cd "$(dirname "$0")/.."
kit=.gpu-kit

prepare() {
  scripts/install-deps.sh
  cmake --preset release
  cmake --build --preset release --target surround-synth surround-bench surround-gpu-check
  synth=build/release/tools/synth/surround-synth
  rm -rf "$kit" && mkdir -p "$kit/pack/bin" "$kit/pack/lib" "$kit/pack/kits"
  # The benchmark recordings' rig, sizes and seed (scripts/bench-recordings.sh), one frame long:
  # only the first frame set's ground truth goes into a kit.
  while read -r name size panorama; do
    "$synth" --rig config/rigs/paper.yaml --out "recordings/gpu-kit/$name" --size "$size" \
      --panorama-size "$panorama" --seconds 0.1 --seed 3 --force >/dev/null
    build/release/tools/bench/surround-bench gpu-kit "$kit/pack/kits" "recordings/gpu-kit/$name"
  done <<INPUTS
480p 854x480 1024x512
720p 1280x720 1536x768
1080p 1920x1080 2048x1024
INPUTS
  program=build/release/tools/gpu_check/surround-gpu-check
  cp "$program" "$kit/pack/bin/"
  # Every library but the C library's own (the machine has its own, as new or newer) and the
  # EGL/GLES loaders (glvnd's, which must find that machine's driver).
  ldd "$program" | awk '$3 ~ /^\// {print $3}' |
    grep -Ev '/(libc|libm|libdl|libpthread|librt|ld-linux-x86-64|libEGL|libGLESv2|libGLdispatch|libGLX|libOpenGL)\.so' |
    while read -r library; do cp -L "$library" "$kit/pack/lib/"; done
  tar -C "$kit/pack" -czf "$kit/gpu-check.tar.gz" .
  rm -rf "$kit/pack"
  du -h "$kit/gpu-check.tar.gz"
}

run() {
  if [ -d .gl ]; then
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
  fi
  if [ -f /usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json ]; then
    export __EGL_VENDOR_LIBRARY_FILENAMES=/usr/local/nvidia/share/glvnd/egl_vendor.d/10_nvidia.json
  fi
  work=$(mktemp -d)
  tar -C "$work" -xzf "$kit/gpu-check.tar.gz"
  report="${OUT:-$kit}/gpu-check.txt"
  frames="${GPU_CHECK_FRAMES:-300}"
  status=0
  {
    if command -v nvidia-smi >/dev/null; then
      nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader
    fi
    for view in orbit top; do
      LD_LIBRARY_PATH="$work/lib" "$work/bin/surround-gpu-check" --frames "$frames" \
        --view "$view" "$work/kits/480p" "$work/kits/720p" "$work/kits/1080p" || status=$?
    done
  } >"$report" 2>&1
  cat "$report"
  rm -rf "$work"
  return "$status"
}

case "${1:-}" in
  prepare) prepare ;;
  run) run ;;
  *) echo "usage: scripts/gpu-check.sh prepare|run" >&2; exit 2 ;;
esac
