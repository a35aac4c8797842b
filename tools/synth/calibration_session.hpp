#pragma once
// A generated calibration session: what a camera sees while someone walks a chessboard around its
// field, for the guided calibration (surround-calibrate guide) and its tests. The board is held
// still at each of a set of poses that cover the field (boardPosesCoveringField) and carried
// from one to the next in between, as a person would; the frames are written as an image
// sequence with the camera's true lens beside them.

#include <filesystem>
#include <functional>
#include <ostream>

#include <opencv2/core.hpp>

#include "processing/calibration/calibration_targets.hpp"
#include "processing/rig.hpp"
#include "tools/synth/synth_options.hpp"

namespace surroundd::synth {

struct SessionPlan {
  processing::Checkerboard board{{9, 6}, 0.05};  // inner corners, square side in metres
  int poses = 12;                                // places the board is held at
  int frames = 60;                               // whole session
  std::uint64_t seed = 1;
  double noiseSigma = 1.5;  // sensor noise, 8-bit levels
};

// Renders the session's frames in order (8-bit BGR, the lens's image size) and hands each to
// `frame` with its index. Throws std::runtime_error when the field cannot hold the board.
void renderCalibrationSession(const processing::Intrinsics& lens, const SessionPlan& plan,
                              const std::function<void(int index, const cv::Mat& bgr)>& frame);

// surround-synth --calibration-session CAMERA: the camera of options.rig, at options.size,
// for options.seconds at options.fps, into options.out: frame_0000.png ... (an image sequence
// for FileSource, "frame_%04d.png") and rig.yaml with that camera alone and its true lens.
void writeCalibrationSession(const SynthOptions& options, std::ostream& log);

}  // namespace surroundd::synth
