#pragma once
// Shared helpers of the generator's tests: reading a recording's ground truth and sampling images.

#include <filesystem>
#include <string>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <yaml-cpp/yaml.h>

#include "tests/support/test_support.hpp"

namespace surroundd::synth::testing {

using surroundd::testing::decodeAll;
using surroundd::testing::fileBytes;

inline std::filesystem::path fixture(const std::string& name) {
  return std::filesystem::path(SURROUNDD_FIXTURE_DIR) / name;
}

// Bilinear sample with pixel centres at integer coordinates (the camera model's convention).
inline cv::Vec3f sampleBilinear(const cv::Mat& image, cv::Point2d p) {
  const int x0 = static_cast<int>(std::floor(p.x));
  const int y0 = static_cast<int>(std::floor(p.y));
  const double ax = p.x - x0, ay = p.y - y0;
  cv::Vec3f out(0, 0, 0);
  for (int dy = 0; dy <= 1; ++dy) {
    for (int dx = 0; dx <= 1; ++dx) {
      const int x = std::clamp(x0 + dx, 0, image.cols - 1);
      const int y = std::clamp(y0 + dy, 0, image.rows - 1);
      const double w = (dx ? ax : 1 - ax) * (dy ? ay : 1 - ay);
      out += cv::Vec3f(image.at<cv::Vec3b>(y, x)) * static_cast<float>(w);
    }
  }
  return out;
}

inline float meanAbsDiff(const cv::Vec3f& a, const cv::Vec3f& b) {
  return (std::abs(a[0] - b[0]) + std::abs(a[1] - b[1]) + std::abs(a[2] - b[2])) / 3;
}

}  // namespace surroundd::synth::testing
