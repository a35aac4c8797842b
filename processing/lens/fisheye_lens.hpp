#pragma once
// The Kannala-Brandt fisheye lens (k1..k4), exactly as cv::fisheye::projectPoints has it for rays
// in front of the lens, and extended past 90 degrees by taking theta = atan2(|xy|, z), which is
// what a 190-degree lens needs.

#include <array>
#include <optional>
#include <string_view>

#include <opencv2/core.hpp>

#include "processing/lens/focal_plane.hpp"
#include "processing/lens/intrinsics.hpp"
#include "processing/lens/radial_polynomial.hpp"

namespace surroundd::processing {

class FisheyeLens {
 public:
  static constexpr LensModel kModel = LensModel::kFisheye;
  static constexpr std::string_view kName = "fisheye";
  static constexpr bool kWideAngle = true;

  explicit FisheyeLens(const Intrinsics& intrinsics);

  const LensField& field() const { return field_; }
  // The normalized image point of a pixel, still distorted.
  cv::Point2d sensorPoint(const cv::Point2d& pixel) const { return plane_.normalized(pixel); }
  std::optional<cv::Point2d> project(const cv::Vec3d& point) const;
  std::optional<cv::Vec3d> unproject(const cv::Point2d& pixel) const;
  cv::Vec2d axisFocalPx() const { return {plane_.fx, plane_.fy}; }

 private:
  FocalPlane plane_;
  std::array<double, 5> d_;
  LensField field_;  // edgeRadius: the distorted radius at the edge of the field
};

}  // namespace surroundd::processing
