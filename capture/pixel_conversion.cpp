#include "capture/pixel_conversion.hpp"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

namespace surroundd::capture {

const char* toString(PixelLayout layout) {
  switch (layout) {
    case PixelLayout::kYuyv:
      return "YUYV";
    case PixelLayout::kUyvy:
      return "UYVY";
    case PixelLayout::kNv12:
      return "NV12";
    case PixelLayout::kBgr:
      return "BGR";
    case PixelLayout::kMjpeg:
      return "MJPEG";
  }
  return "?";
}

bool convertToBgr(PixelLayout layout, std::span<const std::uint8_t> data, std::size_t bytesPerLine,
                  JpegDecoder& jpeg, cv::Mat& bgr, std::string& error) {
  if (layout == PixelLayout::kMjpeg) return jpeg.decode(data, bgr, error);
  const int rows = layout == PixelLayout::kNv12 ? bgr.rows * 3 / 2 : bgr.rows;
  if (data.size() < bytesPerLine * static_cast<std::size_t>(rows)) {
    error = fmt::format("a {} frame of {} bytes is too short for {}x{}", toString(layout),
                        data.size(), bgr.cols, bgr.rows);
    return false;
  }
  auto* pixels = const_cast<std::uint8_t*>(data.data());  // cv::Mat has no read-only header
  switch (layout) {
    case PixelLayout::kYuyv:
    case PixelLayout::kUyvy:
      cv::cvtColor(cv::Mat(bgr.rows, bgr.cols, CV_8UC2, pixels, bytesPerLine), bgr,
                   layout == PixelLayout::kYuyv ? cv::COLOR_YUV2BGR_YUYV : cv::COLOR_YUV2BGR_UYVY);
      return true;
    case PixelLayout::kNv12:
      cv::cvtColor(cv::Mat(rows, bgr.cols, CV_8UC1, pixels, bytesPerLine), bgr,
                   cv::COLOR_YUV2BGR_NV12);
      return true;
    case PixelLayout::kBgr:
      cv::Mat(bgr.rows, bgr.cols, CV_8UC3, pixels, bytesPerLine).copyTo(bgr);
      return true;
    case PixelLayout::kMjpeg:
      break;
  }
  return false;
}

bool convertNv12PlanesToBgr(PlaneView luma, PlaneView chroma, cv::Mat& bgr, std::string& error) {
  const auto rows = static_cast<std::size_t>(bgr.rows);
  const auto cols = static_cast<std::size_t>(bgr.cols);
  if (luma.bytesPerLine < cols || chroma.bytesPerLine < cols ||
      luma.data.size() < luma.bytesPerLine * rows ||
      chroma.data.size() < chroma.bytesPerLine * (rows / 2)) {
    error = fmt::format("a two-plane NV12 frame of {} + {} bytes is too short for {}x{}",
                        luma.data.size(), chroma.data.size(), bgr.cols, bgr.rows);
    return false;
  }
  // cv::Mat has no read-only header; the planes are only read.
  const cv::Mat y(bgr.rows, bgr.cols, CV_8UC1, const_cast<std::uint8_t*>(luma.data.data()),
                  luma.bytesPerLine);
  const cv::Mat uv(bgr.rows / 2, bgr.cols / 2, CV_8UC2,
                   const_cast<std::uint8_t*>(chroma.data.data()), chroma.bytesPerLine);
  cv::cvtColorTwoPlane(y, uv, bgr, cv::COLOR_YUV2BGR_NV12);
  return true;
}

}  // namespace surroundd::capture
