#pragma once
// Intrinsics from board views: OpenCV's calibrateCamera (pinhole + radial-tangential) or
// fisheye::calibrate (Kannala-Brandt), with the residual of every corner measured through the
// project's own CameraModel, so that what is reported is what the stitcher will get, and each
// parameter's standard deviation from the solve's covariance.
//
// Views are in board units: a view's corners sit at their grid (column, row) times one square, so
// the square's size plays no part (the poses come out in squares).

#include <array>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/calibration_board.hpp"
#include "processing/calibration/calibration_error.hpp"
#include "processing/lens/camera_model.hpp"
#include "processing/rig.hpp"

namespace surroundd::processing {

struct ViewResiduals {
  std::string name;
  Pose boardInCamera;                  // X_camera = rotation * X_grid + position, in squares
  std::vector<cv::Point2f> corners;    // as detected
  std::vector<cv::Point2f> residuals;  // reprojected - detected, pixels
  double rmsPx = 0;
  double edgeWidthPx = 0;  // the view's (BoardView::edgeWidthPx)
};

// One standard deviation of each solved parameter, pixels for the focal lengths and principal
// point; distortion in the order of Intrinsics::distortion.
struct IntrinsicsUncertainty {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  std::array<double, 5> distortion{};
};

struct IntrinsicCalibration {
  Intrinsics intrinsics;  // fisheye: maxFieldAngleRad still to be set (see fieldOfViewOf)
  IntrinsicsUncertainty uncertainty;
  double rmsPx = 0;  // over every corner of every view
  std::vector<ViewResiduals> views;
  double startingFocalPx = 0;       // where the solver started from, for the verdict
  double widestCornerAngleRad = 0;  // the largest angle off the optical axis a corner reached
};

// Fewer views than this give focal lengths and distortion that the data barely constrains.
inline constexpr int kMinimumBoardViews = 5;

// Throws CalibrationError for fewer than kMinimumBoardViews views or a failed solve.
IntrinsicCalibration calibrateIntrinsics(LensModel model, cv::Size imageSize,
                                         std::span<const BoardView> views);

struct LitFieldAngle {
  double rad = 0;  // off the optical axis
  // The farthest lit pixel has no ray in the solved model (its distortion turns back short of
  // the image corners, as a pinhole fit to a wide lens often does): `rad` is where the rays end on
  // the way out to it.
  bool pastTheLens = false;
};

// A lens's field, as far as the images show it: the largest angle off the optical axis of any
// pixel set in `litMask` (CV_8U, nonzero where some image was lit; a lens whose image circle lies
// inside the sensor leaves its corners dark), within the model's monotonic range.
LitFieldAngle widestLitFieldAngle(const Intrinsics& intrinsics, const cv::Mat& litMask);

// The fisheye solve's standard deviations, which cv::fisheye::calibrate computes but does not
// return: from the Jacobian of every residual (cv::fisheye::projectPoints) over the 8 lens and
// 6-per-view pose parameters, the lens block of sigma^2 (J^T J)^-1 (the pose blocks eliminated by
// their Schur complement), sigma^2 the residuals' variance over the degrees of freedom.
IntrinsicsUncertainty fisheyeUncertainty(const Intrinsics& lens,
                                         std::span<const std::vector<cv::Point3f>> grids,
                                         std::span<const std::vector<cv::Point2f>> corners,
                                         std::span<const cv::Vec3d> rvecs,
                                         std::span<const cv::Vec3d> tvecs);

}  // namespace surroundd::processing
