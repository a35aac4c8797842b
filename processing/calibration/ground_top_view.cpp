#include "processing/calibration/ground_top_view.hpp"

#include <cmath>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "processing/lens/camera_model.hpp"

namespace surroundd::processing {

GroundSampling groundSampling(const CameraCalibration& camera, const GroundGrid& grid) {
  const CameraModel model(camera.intrinsics);
  GroundSampling sampling{cv::Mat(grid.size, CV_32F, cv::Scalar(-1)),
                          cv::Mat(grid.size, CV_32F, cv::Scalar(-1)), 0};
  const cv::Mat& body = camera.bodyMask;
  for (int row = 0; row < grid.size.height; ++row) {
    for (int column = 0; column < grid.size.width; ++column) {
      const auto pixel = model.project(camera.pose.toCamera(grid.groundAt(row, column)));
      if (!pixel || !model.inImage(*pixel)) continue;
      if (!body.empty() && body.at<std::uint8_t>(static_cast<int>(std::lround(pixel->y)),
                                                 static_cast<int>(std::lround(pixel->x))) != 0) {
        continue;
      }
      sampling.mapX.at<float>(row, column) = static_cast<float>(pixel->x);
      sampling.mapY.at<float>(row, column) = static_cast<float>(pixel->y);
      ++sampling.seen;
    }
  }
  return sampling;
}

cv::Mat stitchedTopView(std::span<const CameraCalibration> cameras, std::span<const cv::Mat> bgr,
                        const GroundGrid& grid) {
  if (cameras.size() != bgr.size()) {
    throw std::invalid_argument("stitchedTopView: one picture per camera");
  }
  cv::Mat sum(grid.size, CV_32FC3, cv::Scalar::all(0));
  cv::Mat count(grid.size, CV_32F, cv::Scalar(0));
  for (std::size_t c = 0; c < cameras.size(); ++c) {
    const auto sampling = groundSampling(cameras[c], grid);
    cv::Mat resampled;
    cv::remap(bgr[c], resampled, sampling.mapX, sampling.mapY, cv::INTER_LINEAR,
              cv::BORDER_CONSTANT, cv::Scalar::all(0));
    const cv::Mat seen = sampling.mapX >= 0;
    cv::Mat asFloat;
    resampled.convertTo(asFloat, CV_32FC3);
    cv::add(sum, asFloat, sum, seen);
    cv::add(count, cv::Scalar(1), count, seen);
  }
  cv::Mat divisor;
  cv::max(count, 1, divisor);
  cv::Mat divisor3;
  cv::merge(std::vector<cv::Mat>{divisor, divisor, divisor}, divisor3);
  cv::Mat view;
  cv::divide(sum, divisor3, sum);
  sum.convertTo(view, CV_8UC3);
  return view;
}

}  // namespace surroundd::processing
