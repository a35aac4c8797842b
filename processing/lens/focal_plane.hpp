#pragma once
// Pixels against the normalized image plane of a lens with focal lengths and a principal point
// (the pinhole and the fisheye models; OCamCalib has an affine matrix instead).

#include <opencv2/core.hpp>

#include "processing/lens/intrinsics.hpp"

namespace surroundd::processing {

struct FocalPlane {
  double fx, fy, cx, cy;

  explicit FocalPlane(const Intrinsics& in) : fx(in.fx), fy(in.fy), cx(in.cx), cy(in.cy) {}
  cv::Point2d normalized(const cv::Point2d& pixel) const {
    return {(pixel.x - cx) / fx, (pixel.y - cy) / fy};
  }
  cv::Point2d pixel(double x, double y) const { return {fx * x + cx, fy * y + cy}; }
};

}  // namespace surroundd::processing
