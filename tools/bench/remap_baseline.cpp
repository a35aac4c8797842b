#include "tools/bench/remap_baseline.hpp"

#include <opencv2/imgproc.hpp>

namespace surroundd::bench {

RemapBaseline::RemapBaseline(const processing::PanoramaLut& lut) {
  const cv::Mat owner = lut.ownerMap();
  for (std::size_t camera = 0; camera < lut.cameraSizes.size(); ++camera) {
    cv::Mat mine;
    cv::compare(owner, cv::Scalar(static_cast<double>(camera)), mine, cv::CMP_EQ);
    const cv::Rect box = cv::boundingRect(mine);
    cv::Mat map(box.size(), CV_32FC2, cv::Scalar(-10, -10));
    const int width = lut.cameraSizes[camera].width;
    for (int v = 0; v < box.height; ++v) {
      for (int u = 0; u < box.width; ++u) {
        const std::size_t index =
            static_cast<std::size_t>(v + box.y) * lut.size.width + (u + box.x);
        const processing::LutTap& tap = lut.taps[index];
        if (tap.camera != camera) continue;
        constexpr float kOne = processing::LutTap::kFractionOne;
        const auto sourceWidth = static_cast<std::uint32_t>(width);
        const std::uint32_t column = tap.offset % sourceWidth;
        const std::uint32_t row = tap.offset / sourceWidth;
        map.at<cv::Vec2f>(v, u) = {static_cast<float>(column) + tap.fx / kOne,
                                   static_cast<float>(row) + tap.fy / kOne};
      }
    }
    CameraMap cameraMap{box, {}, {}};
    cv::convertMaps(map, cv::noArray(), cameraMap.map1, cameraMap.map2, CV_16SC2);
    maps_.push_back(std::move(cameraMap));
  }
}

void RemapBaseline::stitch(std::span<const cv::Mat> frames, cv::Mat& panorama) const {
  for (std::size_t camera = 0; camera < maps_.size(); ++camera) {
    const CameraMap& m = maps_[camera];
    if (m.box.empty()) continue;
    cv::Mat target = panorama(m.box);
    cv::remap(frames[camera], target, m.map1, m.map2, cv::INTER_LINEAR, cv::BORDER_TRANSPARENT);
  }
}

}  // namespace surroundd::bench
