#pragma once
// Camera pixel formats to the pipeline's 8-bit BGR, once per frame, into the frame's own image:
// packed 4:2:2 (YUYV, UYVY), NV12, 24-bit BGR, and MJPEG through libjpeg-turbo. Shared by the
// live sources (V4L2, libcamera).

#include <cstdint>
#include <span>
#include <string>

#include <opencv2/core.hpp>

#include "capture/jpeg_decoder.hpp"

namespace surroundd::capture {

enum class PixelLayout { kYuyv, kUyvy, kNv12, kBgr, kMjpeg };
const char* toString(PixelLayout layout);

// `bytesPerLine` is the stride of the (first) plane. False, with `error` set, for a frame too
// short for its size or an MJPEG frame that does not decode; `bgr` (of the frame's size) is then
// not a valid picture.
bool convertToBgr(PixelLayout layout, std::span<const std::uint8_t> data, std::size_t bytesPerLine,
                  JpegDecoder& jpeg, cv::Mat& bgr, std::string& error);

// One plane of a frame whose planes lie in separate buffers (V4L2 multi-planar formats).
struct PlaneView {
  std::span<const std::uint8_t> data;
  std::size_t bytesPerLine = 0;
};
// NV12 with luma and interleaved chroma in two buffers (V4L2's NV12M). False, with `error` set,
// for a plane too short for the frame's size.
bool convertNv12PlanesToBgr(PlaneView luma, PlaneView chroma, cv::Mat& bgr, std::string& error);

}  // namespace surroundd::capture
