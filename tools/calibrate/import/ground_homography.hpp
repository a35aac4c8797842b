#pragma once
// A camera's pose from a ground-plane homography, as bird's-eye tools store it: H maps a pixel of a
// top-down canvas of the ground to the camera's undistorted image (through its K).
//
// The pose is a least-squares fit over the ground the camera sees, not a bare decomposition of H:
// pixels of the image are taken back through H to the ground they show, and the pose that projects
// those ground points onto their pixels best is solved for (cv::solvePnP, started from the
// decomposition). A homography made from hand-clicked points is seldom exactly a plane seen by a
// camera: decomposed directly, one 12 % off refused to import, a slightly non-planar one gave a
// pose 10 cm and 1 degree off. The fit reports how far it is from H, in pixels and on the ground.

#include <string>

#include <opencv2/core.hpp>

#include "tools/calibrate/import/source_frame.hpp"

namespace surroundd::calibrate {

struct GroundCanvas {
  double scale = 1;    // source units per canvas pixel
  cv::Point2d origin;  // the canvas pixel of the source origin
  double groundZ = 0;  // the canvas plane, on the source z axis
  double upSign = 1;   // +1 when the source z axis points up, -1 down
};

struct GroundPoseFit {
  CameraFromSource pose;
  int points = 0;             // ground points fitted
  double rmsPx = 0;           // between H's pixels and the fitted pose's, over those points
  double rmsGroundUnits = 0;  // between H's ground points and the fitted pose's, source units
};

// The pose that best explains H over the ground the camera sees (within ten camera heights). A
// homography no camera above the ground explains (its decomposition degenerate, the fitted camera
// under the ground, or too few ground points in view) throws UsageError naming H's origin.
GroundPoseFit poseFromGroundHomography(const cv::Matx33d& homography, const cv::Matx33d& camera,
                                       cv::Size imageSize, const GroundCanvas& canvas,
                                       const std::string& origin);

}  // namespace surroundd::calibrate
