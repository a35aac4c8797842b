#pragma once
// Scaramuzza's OCamCalib lens, which many automotive kits ship: its world2cam / cam2world exactly
// for rays in front of the lens, extended past 90 degrees the same way as the fisheye.

#include <optional>
#include <string_view>

#include <opencv2/core.hpp>

#include "processing/lens/intrinsics.hpp"
#include "processing/lens/radial_polynomial.hpp"

namespace surroundd::processing {

class OcamLens {
 public:
  static constexpr LensModel kModel = LensModel::kOcam;
  static constexpr std::string_view kName = "ocam";
  static constexpr bool kWideAngle = true;

  explicit OcamLens(const Intrinsics& intrinsics);

  const LensField& field() const { return field_; }
  // The sensor-plane point of a pixel, in pixels before the affine matrix.
  cv::Point2d sensorPoint(const cv::Point2d& pixel) const;
  std::optional<cv::Point2d> project(const cv::Vec3d& point) const;
  std::optional<cv::Vec3d> unproject(const cv::Point2d& pixel) const;
  // The slope of rho(theta) on the axis, through the affine matrix (ocam has no focal length).
  cv::Vec2d axisFocalPx() const;

 private:
  double cx_, cy_;
  Intrinsics::Ocam ocam_;
  LensField field_;     // edgeRadius: rho in pixels at the edge of the field
  double axisRho_ = 0;  // rho on the axis, which a fitted polynomial leaves slightly off 0
};

}  // namespace surroundd::processing
