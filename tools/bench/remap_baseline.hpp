#pragma once
// The baseline the stitcher is measured against: OpenCV's cv::remap on the same LUT. Each camera
// gets its own fixed-point map (cv::convertMaps, OpenCV's fastest form) over the bounding box of
// the panorama pixels it owns; other pixels in the box map outside the image and are left alone
// (BORDER_TRANSPARENT). It does not blend the seams, so it does less work than the stitcher.

#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/stitch/panorama_lut.hpp"

namespace surroundd::bench {

class RemapBaseline {
 public:
  explicit RemapBaseline(const processing::PanoramaLut& lut);
  void stitch(std::span<const cv::Mat> frames, cv::Mat& panorama) const;

 private:
  struct CameraMap {
    cv::Rect box;  // in the panorama
    cv::Mat map1, map2;
  };
  std::vector<CameraMap> maps_;
};

}  // namespace surroundd::bench
