#pragma once
// Flat printed calibration targets (checkerboards, ArUco markers) rendered through a camera's lens
// model, for calibration tests with known truth.
//
// Why a renderer of its own and not the scene's: calibration accuracy is judged at a twentieth of a
// pixel, so an edge must be where the lens model puts it, at any field angle. Every pixel is
// integrated over a grid of sub-pixel rays, each unprojected exactly by processing::CameraModel
// and intersected with the target planes; the sensor then applies the generator's photometric
// model (gain, gamma, vignetting, noise). The sub-pixel rays depend only on the lens, so they are
// computed once per camera and reused for every view.

#include <cstdint>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/calibration_targets.hpp"
#include "processing/lens/camera_model.hpp"
#include "processing/rig.hpp"
#include "tools/synth/photometrics.hpp"

namespace surroundd::synth {

// The print of one target: reflectance in its pattern frame
// (processing/calibration/calibration_targets.hpp), a white margin around it included.
class TargetPattern {
 public:
  static TargetPattern checkerboard(const processing::Checkerboard& board);
  static TargetPattern aruco(int dictionary, int id, double sideM);
  // A ChArUco board of `squares` (columns x rows) as OpenCV draws it, its top-left square's
  // outer corner at the pattern origin, then a white margin of one square. Its inner corner
  // (i, j) lies at ((i + 1), (j + 1)) * squareM, as a chessboard's lies at (i, j) * squareM.
  static TargetPattern charuco(cv::Size squares, int dictionary, double markerToSquare,
                               double squareM);

  // Reflectance, 0..1, at a pattern point; nullopt off the print.
  std::optional<float> albedo(double u, double v) const;

 private:
  TargetPattern() = default;

  cv::Mat modules_;  // CV_8U, one element per square or marker module, 0 black / 1 white
  double moduleM_ = 0;
  cv::Point2d moduleOrigin_;  // pattern coordinates of module (0, 0)'s top-left corner
};

// A target placed in the scene: pattern point (u, v) lies at origin + u * uAxis + v * vAxis.
struct PlacedTarget {
  TargetPattern pattern;
  cv::Vec3d origin;
  cv::Vec3d uAxis;
  cv::Vec3d vAxis;  // unit, orthogonal to uAxis
};

// Placing a ground marker (vehicle frame) or a board posed in a camera (X_camera = rotation *
// X_pattern + position).
PlacedTarget placeGroundMarker(const processing::GroundMarker& marker, int arucoDictionary);
PlacedTarget placeBoard(const processing::Checkerboard& board,
                        const processing::Pose& boardInCamera);
PlacedTarget placePattern(TargetPattern pattern, const processing::Pose& patternInCamera);

struct TargetScene {
  std::vector<PlacedTarget> targets;
  // Scene frame z = 0 is a grey floor seen below the horizon, with a bright sky above (the vehicle
  // frame of ground-marker views); otherwise everything behind the targets is a grey wall.
  bool floor = false;
};

class TargetRenderer {
 public:
  // `supersampling`: sub-pixel rays per pixel side (4: sixteen per pixel).
  TargetRenderer(const processing::Intrinsics& intrinsics, int supersampling);

  // The image (8-bit BGR) of a camera at `cameraPose` (X_scene = rotation * X_camera + position),
  // through `photometrics`; noise is a pure function of (seed, frameIndex, pixel). Pixels outside a
  // fisheye's image circle are black.
  cv::Mat render(const processing::Pose& cameraPose, const TargetScene& scene,
                 const CameraPhotometrics& photometrics, std::uint64_t seed, int frameIndex) const;

 private:
  cv::Size size_;
  int samples_;  // per pixel side
  bool fisheye_;
  std::vector<cv::Vec3f> rays_;  // camera frame, unit; NaN outside the lens; pixel-major
  cv::Mat offAxisAngle_;         // CV_32F per pixel centre, -1 outside the lens
};

}  // namespace surroundd::synth
