#pragma once
// What a camera hands over into a frame's own image, once per frame: YUYV and NV12 kept as they
// are (the stitch samples them directly, common/pixel_format.hpp); packed UYVY, 24-bit BGR and
// MJPEG (through libjpeg-turbo) converted to 8-bit BGR. Shared by the live sources (V4L2,
// libcamera) and the preloaded replay.

#include <cstdint>
#include <span>
#include <string>

#include <opencv2/core.hpp>

#include "capture/jpeg_decoder.hpp"
#include "common/pixel_format.hpp"

namespace surroundd::capture {

enum class PixelLayout { kYuyv, kUyvy, kNv12, kBgr, kMjpeg };
const char* toString(PixelLayout layout);

// `bytesPerLine` is the stride of the (first) plane. False, with `error` set, for a frame too
// short for its size or an MJPEG frame that does not decode; `bgr` (of the frame's size) is then
// not a valid picture.
bool convertToBgr(PixelLayout layout, std::span<const std::uint8_t> data, std::size_t bytesPerLine,
                  JpegDecoder& jpeg, cv::Mat& bgr, std::string& error);

// How a frame delivered in `layout` is held: YUYV, UYVY and NV12 as they came, the others as BGR.
PixelFormat heldFormat(PixelLayout layout);
// A delivered frame into `held`, a picture of `size` held in heldFormat(layout) (allocated by the
// frame's pool): YUYV, UYVY and NV12 copied without the driver's row padding, the others converted
// by convertToBgr. False, with `error` set, as convertToBgr.
bool holdFrame(PixelLayout layout, std::span<const std::uint8_t> data, std::size_t bytesPerLine,
               JpegDecoder& jpeg, cv::Size size, cv::Mat& held, std::string& error);

// One plane of a frame whose planes lie in separate buffers (V4L2 multi-planar formats).
struct PlaneView {
  std::span<const std::uint8_t> data;
  std::size_t bytesPerLine = 0;
};
// NV12 with luma and interleaved chroma in two buffers (V4L2's NV12M), into `held`: a picture of
// `size` held as NV12. False, with `error` set, for a plane too short for the frame's size.
bool holdNv12Planes(PlaneView luma, PlaneView chroma, cv::Size size, cv::Mat& held,
                    std::string& error);

}  // namespace surroundd::capture
