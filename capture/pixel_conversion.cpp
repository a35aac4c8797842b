#include "capture/pixel_conversion.hpp"

#include <cstring>

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

PixelFormat heldFormat(PixelLayout layout) {
  switch (layout) {
    case PixelLayout::kYuyv:
      return PixelFormat::kYuyv;
    case PixelLayout::kNv12:
      return PixelFormat::kNv12;
    case PixelLayout::kUyvy:
      return PixelFormat::kUyvy;
    case PixelLayout::kBgr:
    case PixelLayout::kMjpeg:
      break;
  }
  return PixelFormat::kBgr;
}

namespace {

// `rows` rows of `rowBytes` each, `bytesPerLine` apart in `data`, into the continuous `to`.
bool copyRows(std::span<const std::uint8_t> data, std::size_t bytesPerLine, std::size_t rowBytes,
              std::size_t rows, std::uint8_t* to) {
  if (rows == 0) return true;
  if (bytesPerLine < rowBytes || data.size() < bytesPerLine * (rows - 1) + rowBytes) return false;
  for (std::size_t r = 0; r < rows; ++r) {
    std::memcpy(to + r * rowBytes, data.data() + r * bytesPerLine, rowBytes);
  }
  return true;
}

}  // namespace

bool holdFrame(PixelLayout layout, std::span<const std::uint8_t> data, std::size_t bytesPerLine,
               JpegDecoder& jpeg, cv::Size size, cv::Mat& held, std::string& error) {
  const PixelFormat format = heldFormat(layout);
  if (format == PixelFormat::kBgr)
    return convertToBgr(layout, data, bytesPerLine, jpeg, held, error);
  const cv::Size rows = heldSize(format, size);
  const std::size_t rowBytes =
      static_cast<std::size_t>(rows.width) * CV_ELEM_SIZE(heldType(format));
  if (!copyRows(data, bytesPerLine, rowBytes, static_cast<std::size_t>(rows.height),
                held.ptr<std::uint8_t>())) {
    error = fmt::format("a {} frame of {} bytes ({} per line) is too short for {}x{}",
                        toString(layout), data.size(), bytesPerLine, size.width, size.height);
    return false;
  }
  return true;
}

bool holdNv12Planes(PlaneView luma, PlaneView chroma, cv::Size size, cv::Mat& held,
                    std::string& error) {
  const auto rows = static_cast<std::size_t>(size.height);
  const auto cols = static_cast<std::size_t>(size.width);
  if (!copyRows(luma.data, luma.bytesPerLine, cols, rows, held.ptr<std::uint8_t>()) ||
      !copyRows(chroma.data, chroma.bytesPerLine, cols, rows / 2,
                held.ptr<std::uint8_t>(size.height))) {
    error = fmt::format("a two-plane NV12 frame of {} + {} bytes is too short for {}x{}",
                        luma.data.size(), chroma.data.size(), size.width, size.height);
    return false;
  }
  return true;
}

}  // namespace surroundd::capture
