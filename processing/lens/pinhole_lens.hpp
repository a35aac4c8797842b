#pragma once
// The pinhole lens with OpenCV's radial-tangential distortion (k1, k2, p1, p2, k3), exactly as
// cv::projectPoints has it, so calibrations from calibrateCamera drop in unchanged. It sees only
// what is in front of it, and its field is its picture's.

#include <array>
#include <optional>
#include <string_view>

#include <opencv2/core.hpp>

#include "processing/lens/focal_plane.hpp"
#include "processing/lens/intrinsics.hpp"
#include "processing/lens/radial_polynomial.hpp"

namespace surroundd::processing {

class PinholeLens {
 public:
  static constexpr LensModel kModel = LensModel::kPinhole;
  static constexpr std::string_view kName = "pinhole";
  static constexpr bool kWideAngle = false;

  explicit PinholeLens(const Intrinsics& intrinsics);

  const LensField& field() const { return field_; }
  // The normalized image point of a pixel, still distorted.
  cv::Point2d sensorPoint(const cv::Point2d& pixel) const { return plane_.normalized(pixel); }
  std::optional<cv::Point2d> project(const cv::Vec3d& point) const;
  std::optional<cv::Vec3d> unproject(const cv::Point2d& pixel) const;
  cv::Vec2d axisFocalPx() const { return {plane_.fx, plane_.fy}; }

 private:
  FocalPlane plane_;
  std::array<double, 5> d_;
  double maxRadius_ = 0;  // the undistorted normalized radius at the edge of the valid field
  LensField field_;
};

}  // namespace surroundd::processing
