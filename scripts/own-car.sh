#!/bin/sh
# docs/your-own-car.md, "From chessboard pictures to a top view", end to end: a car whose lenses
# are calibrated from chessboard pictures, whose poses come from one picture each of a calibration
# mat, whose body is found in a recorded drive, and no line of code. The car is the generator's
# (config/rigs/fisheye-body.yaml: fisheye cameras in the bumpers and under the mirrors), so that
# each step's result can be held against the truth it was made from; with a real car, its own
# pictures and recordings take the place of step 1.
#
# Usage: scripts/own-car.sh [OUT]   (default out/own-car; the tools of build/release, or of BUILD)
set -eu
cd "$(dirname "$0")/.."
build=${BUILD:-build/release}
out=${1:-out/own-car}
synth=$build/tools/synth/surround-synth
calibrate=$build/tools/calibrate/surround-calibrate
surroundd=$build/daemon/surroundd
truth=config/rigs/fisheye-body.yaml # only the generator reads it
cameras="front right back left"
for tool in "$synth" "$calibrate" "$surroundd"; do
  [ -x "$tool" ] || { echo "own-car: $tool is not built (cmake --build --preset release)" >&2; exit 2; }
done
rm -rf "$out"
mkdir -p "$out"
step() { printf '\n== %s\n' "$*"; }

step "1. What the car gives: each camera's chessboard pictures, a mat's pictures, a drive"
for camera in $cameras; do
  "$synth" --rig "$truth" --calibration-session "$camera" --out "$out/boards/$camera" \
    --seconds 12 --fps 2
done
"$synth" --rig "$truth" --calibration-mat 7x6@0.2 --out "$out/mat"
"$synth" --rig "$truth" --out "$out/drive" --seconds 10 --fps 5 --panorama-size 512x256
rm "$out/mat/rig.yaml" "$out/drive/rig.yaml" "$out/drive/ground_truth.yaml" # no peeking

step "2. The rig as measured on the car with a tape, the lenses as their datasheet says"
cat >"$out/rig.yaml" <<'EOF'
# Where each camera is and roughly where it looks (a tape, a protractor); the lenses are the
# datasheet's 190-degree fisheye until calibrated.
cameras:
  - name: front
    source: {file: drive/front.mkv}
    lens: {model: fisheye, width_px: 1280, height_px: 720, fx_px: 350, fy_px: 350, cx_px: 640,
           cy_px: 360, distortion: [0, 0, 0, 0], field_of_view_deg: 190}
    mount: {x_m: 2.25, y_m: 0.0, z_m: 0.65, yaw_deg: 0, pitch_deg: -15, roll_deg: 0}
  - name: right
    source: {file: drive/right.mkv}
    lens: {model: fisheye, width_px: 1280, height_px: 720, fx_px: 350, fy_px: 350, cx_px: 640,
           cy_px: 360, distortion: [0, 0, 0, 0], field_of_view_deg: 190}
    mount: {x_m: 0.95, y_m: -1.0, z_m: 1.05, yaw_deg: -90, pitch_deg: -45, roll_deg: 0}
  - name: back
    source: {file: drive/back.mkv}
    lens: {model: fisheye, width_px: 1280, height_px: 720, fx_px: 350, fy_px: 350, cx_px: 640,
           cy_px: 360, distortion: [0, 0, 0, 0], field_of_view_deg: 190}
    mount: {x_m: -2.3, y_m: 0.0, z_m: 0.95, yaw_deg: 180, pitch_deg: -30, roll_deg: 0}
  - name: left
    source: {file: drive/left.mkv}
    lens: {model: fisheye, width_px: 1280, height_px: 720, fx_px: 350, fy_px: 350, cx_px: 640,
           cy_px: 360, distortion: [0, 0, 0, 0], field_of_view_deg: 190}
    mount: {x_m: 0.95, y_m: 1.0, z_m: 1.05, yaw_deg: 90, pitch_deg: -45, roll_deg: 0}
vehicle: {length_m: 4.6, width_m: 1.85, height_m: 1.5, ground_clearance_m: 0.15,
          front_overhang_m: 0.95, rear_overhang_m: 1.0}
EOF

step "3. Each lens from its chessboard pictures (9x6 inner corners, 5 cm squares)"
for camera in $cameras; do
  "$calibrate" intrinsics --images "$out/boards/$camera" --board 9x6 --square 50 --model fisheye \
    --field-of-view-deg 190 --out "$out/lens-$camera.yaml" --update-rig "$out/rig.yaml" \
    --camera "$camera"
done

step "4. Every pose from the mat's pictures"
"$calibrate" extrinsics --rig "$out/rig.yaml" --mat "$out/mat/mat.yaml" --images "$out/mat" \
  --out "$out/mounts.yaml" --update-rig

step "5. The body, found in the drive, pasted into the rig"
"$calibrate" mask --from "$out/rig.yaml" --out "$out/masks" | tee "$out/masks.txt"
# The printed "  - name: NAME" / "    body_mask: {...}" pairs, each mask put under its camera.
awk '
  FNR == NR { if ($1 == "-" && $2 == "name:") name = $3
              else if ($1 == "body_mask:" && name != "") { mask[name] = $0; name = "" }
              next }
  { print }
  $1 == "-" && $2 == "name:" && ($3 in mask) { print mask[$3] }
' "$out/masks.txt" "$out/rig.yaml" >"$out/rig-masked.yaml"
mv "$out/rig-masked.yaml" "$out/rig.yaml"

step "6. The config, checked, and the top view of the drive"
cat >"$out/config.yaml" <<'EOF'
rig: {file: rig.yaml}
panorama: {width_px: 1024, height_px: 512}
calibration_watch: {interval_s: 1}
outputs:
  - {type: snapshot, stream: surround, view: top, path: top.png, at_s: 9}
  - {type: snapshot, stream: panorama, path: panorama.png, at_s: 9}
EOF
"$surroundd" --check-config --config "$out/config.yaml"
"$surroundd" --config "$out/config.yaml" --pacing as_fast_as_possible 2>&1 | tee "$out/surroundd.log" |
  grep -E "calibration watch|body mask|wrote|contributes" || true
echo
echo "own-car: the rig is $out/rig.yaml, the top view $out/top.png"
