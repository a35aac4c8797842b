#pragma once
// Intrinsics from checkerboard views: OpenCV's calibrateCamera (pinhole + radial-tangential) or
// fisheye::calibrate (Kannala-Brandt), with the residual of every corner measured through the
// project's own CameraModel, so that what is reported is what the stitcher will get.

#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration_error.hpp"
#include "processing/calibration_targets.hpp"
#include "processing/camera_model.hpp"
#include "processing/rig.hpp"

namespace surroundd::processing {

struct BoardView {
  std::string name;                  // for reports, e.g. the image file
  std::vector<cv::Point2f> corners;  // the board's inner corners in its own order, pixels
};

struct ViewResiduals {
  std::string name;
  Pose boardInCamera;                  // X_camera = rotation * X_pattern + position
  std::vector<cv::Point2f> corners;    // as detected
  std::vector<cv::Point2f> residuals;  // reprojected - detected, pixels
  double rmsPx = 0;
};

struct IntrinsicCalibration {
  Intrinsics intrinsics;  // fisheye: maxFieldAngleRad still to be set (see widestLitFieldAngle)
  double rmsPx = 0;       // over every corner of every view
  std::vector<ViewResiduals> views;
};

// Fewer views than this give focal lengths and distortion that the data barely constrains.
inline constexpr int kMinimumBoardViews = 5;

// Throws CalibrationError for fewer than kMinimumBoardViews views or a failed solve.
IntrinsicCalibration calibrateIntrinsics(LensModel model, cv::Size imageSize,
                                         const Checkerboard& board,
                                         std::span<const BoardView> views);

// A fisheye lens's field, as far as the images show it: the largest angle off the optical axis
// of any pixel set in `litMask` (CV_8U, nonzero where some image was lit; a lens whose image circle
// lies inside the sensor leaves its corners dark). Radians, within the model's monotonic range.
double widestLitFieldAngle(const Intrinsics& intrinsics, const cv::Mat& litMask);

}  // namespace surroundd::processing
