#pragma once
// A calibration mat laid around a rig as on a production line: one large checkerboard in the
// overlap of each pair of neighbouring cameras (seen whole by both), and optionally one straight
// ahead of chosen cameras. Pure function of the rig and the request; render it with
// TargetRenderer (placeGroundMarker of each board's print, on a floor).

#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "processing/calibration/ground_mat.hpp"
#include "processing/rig.hpp"

namespace surroundd::synth {

struct GroundMatRequest {
  processing::Checkerboard board{{7, 6}, 0.2};
  // Cameras that also get a board of their own straight ahead (e.g. front and back).
  std::vector<std::string> boardAhead;
};

// Each board as near the car as it fits, square to the vehicle's axes where it can be, outside the
// box of the camera positions (where the car stands). Throws std::runtime_error naming the
// cameras when no place fits a board.
processing::MatLayout groundMatAroundRig(std::span<const processing::CameraCalibration> cameras,
                                         const GroundMatRequest& request);

// The mat's prints as ground markers, for the renderer.
processing::MarkerLayout printsOf(const processing::MatLayout& mat);

// A mount a few centimetres and degrees off `truth` (4, -3, 5 cm; yaw +2, pitch -1.5, roll +1
// degrees): what a rig file says before calibration, as measured by hand. The mat calibration
// starts from it and must find `truth`.
processing::Pose mountMeasuredByHand(const processing::Pose& truth);

// The layout as surround-calibrate extrinsics --mat reads it (tools/calibrate/marker_file.hpp),
// `comment` on top.
std::string matYaml(const processing::MatLayout& mat, std::string_view comment);

}  // namespace surroundd::synth
