#pragma once
// A camera's pose from a ground-plane homography, as bird's-eye tools store it: H maps a pixel of a
// top-down canvas of the ground to the camera's undistorted image (through its K).

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "tools/calibrate/source_frame.hpp"

namespace surroundd::calibrate {

struct GroundCanvas {
  double scale = 1;    // source units per canvas pixel
  cv::Point2d origin;  // the canvas pixel of the source origin
  double groundZ = 0;  // the canvas plane, on the source z axis
  double upSign = 1;   // +1 when the source z axis points up, -1 down
};

// Decomposes H = K [r1 r2 t] S^-1 (S: ground (x, y) to canvas pixels) and keeps the sign that puts
// the camera above the ground. `error` names H's origin when it is not a plane seen by a pinhole
// (a column of K^-1 H S collapsing, or r1 and r2 far from perpendicular).
CameraFromSource poseFromGroundHomography(const cv::Matx33d& homography, const cv::Matx33d& camera,
                                          const GroundCanvas& canvas, const std::string& origin);

}  // namespace surroundd::calibrate
