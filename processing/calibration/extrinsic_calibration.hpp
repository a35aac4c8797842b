#pragma once
// A camera's pose on the vehicle from points at known vehicle-frame positions and their pixels.
//
// The pixels are first turned into rays with the project's CameraModel, so a fisheye's points work
// up to the edge of its field. A first pose comes from RANSAC over minimal P3P solutions
// (cv::solvePnPRansac) in a virtual pinhole view centred on the rays, which throws out gross
// mismatches; it is then refined by Levenberg-Marquardt on the reprojection error in the real
// image, with Huber weights so that a corner detected a little off cannot pull the pose, over
// every point (those past 90 degrees off axis included). Points that still miss by more than the
// inlier threshold are left out and the pose refined once more.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/calibration_error.hpp"
#include "processing/lens/camera_model.hpp"
#include "processing/rig.hpp"

namespace surroundd::processing {

struct PointCorrespondence {
  cv::Vec3d vehicle;  // metres, vehicle frame
  cv::Point2d pixel;  // where the camera sees it
  std::string label;  // for messages, e.g. "board front_left corner 7"
};

struct ExtrinsicSettings {
  double inlierThresholdPx = 3.0;  // a point whose reprojection misses by more is an outlier
  double huberPx = 0.5;            // residuals beyond this weigh linearly, not quadratically
  int ransacIterations = 1000;
  // The pose assumed so far (T_vehicle_camera), e.g. the rig's mount. When given, the refinement
  // also starts from it and the start that ends with the lower cost wins: RANSAC over one planar
  // board seen at a grazing angle can settle on the board's mirror-image pose.
  std::optional<Pose> prior;
};

struct ExtrinsicCalibration {
  Pose pose;                             // T_vehicle_camera
  double rmsPx = 0;                      // over the inliers
  std::vector<cv::Point2d> reprojected;  // per correspondence, NaN where it does not project
  std::vector<bool> inlier;
  int inlierCount = 0;
};

// Enough to fix six degrees of freedom with some redundancy against a bad point.
inline constexpr int kMinimumPosePoints = 6;

// Throws CalibrationError for fewer than kMinimumPosePoints points, a pixel outside the lens (named
// by its label), points that are not spread enough to fix a pose, or too few inliers.
ExtrinsicCalibration calibrateExtrinsics(const Intrinsics& intrinsics,
                                         std::span<const PointCorrespondence> points,
                                         const ExtrinsicSettings& settings = {});

}  // namespace surroundd::processing
