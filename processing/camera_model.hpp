#pragma once
// Lens models: where a 3D point in the camera frame lands in the image, and back.
//
// Camera frame is OpenCV's: x right, y down, z forward (optical axis). Both models match OpenCV
// exactly where OpenCV defines them (cv::projectPoints for pinhole + radial-tangential,
// cv::fisheye::projectPoints for Kannala-Brandt), so calibrations from calib3d drop in unchanged.
// The fisheye model is extended past 90 degrees by taking theta = atan2(|xy|, z), which is what a
// 190-degree lens needs and agrees with OpenCV for z > 0.

#include <array>
#include <optional>

#include <opencv2/core.hpp>

namespace surroundd::processing {

enum class LensModel { kPinhole, kFisheye };

struct Intrinsics {
  LensModel model = LensModel::kPinhole;
  cv::Size imageSize;     // pixels
  double fx = 0, fy = 0;  // focal lengths, pixels
  double cx = 0, cy = 0;  // principal point, pixels (pixel centres at integer coordinates)
  // Pinhole: k1, k2, p1, p2, k3 (OpenCV order). Fisheye: k1, k2, k3, k4; the fifth is unused (0).
  std::array<double, 5> distortion{};
  // Fisheye only: rays further than this from the optical axis are outside the lens (radians).
  // Pinhole: rays must have z > 0 and stay inside the monotonic part of the distortion.
  double maxFieldAngleRad = 0;

  bool operator==(const Intrinsics&) const = default;
};

class CameraModel {
 public:
  explicit CameraModel(const Intrinsics& intrinsics);

  // Pixel of a camera-frame point; nullopt when the point is behind the lens or outside its field.
  // The pixel may still lie outside the image; use inImage() for that.
  std::optional<cv::Point2d> project(const cv::Vec3d& pointCamera) const;

  // Unit ray in the camera frame through a pixel; nullopt when the pixel is outside the lens's
  // valid image circle (fisheye) or the distortion cannot be inverted there.
  std::optional<cv::Vec3d> unproject(const cv::Point2d& pixel) const;

  bool inImage(const cv::Point2d& pixel) const;
  const Intrinsics& intrinsics() const { return intrinsics_; }

 private:
  Intrinsics intrinsics_;
  double maxRadius_ = 0;  // normalized-image radius at the edge of the valid field
};

}  // namespace surroundd::processing
