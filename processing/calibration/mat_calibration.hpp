#pragma once
// Every camera's pose from one picture each of a calibration mat (ground_mat.hpp), with a verdict.
//
// Each camera's boards are found (mat_board_detection.hpp) and its pose solved from all their
// corners with its lens model (calibrateExtrinsics: RANSAC, then robust Levenberg-Marquardt). A
// board that two cameras see is the check between them: each camera's corners, cast onto the
// ground through its solved pose, must land where the other camera's land (the seam error). A
// camera passes when all its boards were found, it has enough corners, the corners reproject
// within the RMS limit and the pose is near enough the nominal mount to be believed; the run passes
// when every camera and every seam does. Nothing here writes anything: the caller writes only a
// run that passed.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/extrinsic_calibration.hpp"
#include "processing/calibration/ground_mat.hpp"
#include "processing/calibration/mat_board_detection.hpp"
#include "processing/rig.hpp"

namespace surroundd::processing {

struct MatView {
  CameraCalibration nominal;  // the lens and the mount assumed so far (a rig file's)
  cv::Mat gray;               // CV_8U picture of the mat, the lens's size
};

struct MatLimits {
  int minCorners = 20;     // per camera: a pose from fewer is not worth believing
  double maxRmsPx = 1.0;   // reprojection RMS per camera
  double maxShiftM = 0.5;  // solved position against the nominal mount
  double maxTurnDeg = 15;  // solved rotation against the nominal mount
  double maxSeamCm = 3.0;  // RMS ground distance between two cameras' corners of a shared board
};

struct MatBoardResidual {
  std::size_t board = 0;
  int corners = 0;
  double rmsPx = 0;
};

struct MatCameraResult {
  std::string camera;
  MatBoardDetection detection;
  int corners = 0;
  std::optional<ExtrinsicCalibration> solve;  // absent when it could not be tried or failed
  std::vector<MatBoardResidual> boards;       // per board found, with the solved pose
  double shiftM = 0;                          // from the nominal mount
  double turnDeg = 0;
  std::vector<std::string> problems;  // why it failed; empty: passed
  bool passed() const { return problems.empty(); }
};

struct MatSeam {
  std::size_t board = 0;
  std::string first, second;  // the cameras
  int corners = 0;
  double rmsCm = 0;  // ground distance between where the two cameras put each corner
  double maxCm = 0;
};

struct MatCalibration {
  std::vector<MatCameraResult> cameras;  // in the order of the views
  std::vector<MatSeam> seams;            // boards shared by two cameras that both solved
  std::vector<std::string> problems;     // seams: missing or over the limit
  bool passed() const;
};

// Throws CalibrationError when a board names a camera that has no view, or a view's picture does
// not match its lens size; every other failure is a problem in the result.
MatCalibration calibrateFromMat(const MatLayout& layout, std::span<const MatView> views,
                                const MatLimits& limits = {},
                                const MatDetectionSettings& detection = {},
                                const ExtrinsicSettings& solve = {});

}  // namespace surroundd::processing
