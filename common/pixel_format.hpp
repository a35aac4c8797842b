#pragma once
// How a camera frame's pixels are held on their way from capture to the stitch: 8-bit BGR, or the
// YUV the camera handed over, kept as it came so that only the pixels a picture needs are ever
// converted (a 1280x720 view of four 1920x1080 cameras samples a ninth of their pixels). YUYV is
// packed 4:2:2 (Y0 Cb Y1 Cr per two pixels, the chroma shared by both), UYVY the same with the
// chroma first (Cb Y0 Cr Y1: what most automotive serializer links carry); NV12 is the luma plane
// and then one interleaved Cb Cr pair per 2x2 pixels. YUV is BT.601, limited range (luma 16..235,
// chroma 16..240 around 128), as V4L2 cameras deliver it.

#include <cstddef>
#include <cstdint>

#include <opencv2/core.hpp>

#include "common/bt601.hpp"

namespace surroundd {

enum class PixelFormat : std::uint8_t { kBgr, kYuyv, kNv12, kUyvy };
inline constexpr std::size_t kPixelFormats = 4;

const char* toString(PixelFormat format);

// The cv::Mat that holds a picture of `size` in `format`: BGR CV_8UC3 of `size`; YUYV, UYVY
// CV_8UC2 of `size`; NV12 CV_8UC1 of width x height * 3 / 2, luma rows then chroma rows. YUV needs
// an even width, NV12 an even height too.
int heldType(PixelFormat format);
cv::Size heldSize(PixelFormat format, cv::Size pictureSize);
// The picture size of a held frame: heldSize()'s inverse.
cv::Size pictureSize(PixelFormat format, const cv::Mat& held);
// Whether `held` is a continuous frame of `format` holding a picture of `size`.
bool holds(const cv::Mat& held, PixelFormat format, cv::Size size);
// A picture of `size` in `format` that is black once converted (YUV: luma 16, chroma 128).
cv::Mat blackPicture(PixelFormat format, cv::Size size);

// A whole held frame to BGR, as cv::cvtColor converts it (`bgr` is reallocated only if it is not
// already of the picture's size). BGR is copied.
void heldToBgr(const cv::Mat& held, PixelFormat format, cv::Mat& bgr);

// A BGR picture (of even width; NV12: and height) held in `format`, as a camera of that format
// would deliver it: BT.601 limited range, what heldToBgr() converts back. `held` is reallocated
// only if it is not already of the right size and type. Not for the per-frame path: start-up
// (preloading a recording) and tests.
void bgrToHeld(const cv::Mat& bgr, PixelFormat format, cv::Mat& held);

// One pixel of YUV to BGR, as cv::cvtColor converts it (common/bt601.hpp).
using bt601::yuvToBgr;

// Pixel (x, y) of a held picture as B | G << 8 | R << 16: for a few pixels of a frame (camera
// health's samples), where converting the frame would cost more than the pixels.
inline std::uint32_t bgrAt(const cv::Mat& held, PixelFormat format, int x, int y) {
  const std::uint8_t* row = held.ptr<std::uint8_t>(y);
  switch (format) {
    case PixelFormat::kYuyv:
    case PixelFormat::kUyvy: {
      const std::size_t luma = format == PixelFormat::kYuyv ? 0 : 1;
      const std::uint8_t* pair = row + 4 * static_cast<std::size_t>(x / 2);
      return yuvToBgr(row[2 * static_cast<std::size_t>(x) + luma] |
                      std::uint32_t{pair[1 - luma]} << 8 | std::uint32_t{pair[3 - luma]} << 16);
    }
    case PixelFormat::kNv12: {
      const std::uint8_t* pair =
          held.ptr<std::uint8_t>(held.rows * 2 / 3 + y / 2) + static_cast<std::size_t>(x & ~1);
      return yuvToBgr(row[x] | std::uint32_t{pair[0]} << 8 | std::uint32_t{pair[1]} << 16);
    }
    case PixelFormat::kBgr:
      break;
  }
  const std::uint8_t* pixel = row + 3 * static_cast<std::size_t>(x);
  return pixel[0] | std::uint32_t{pixel[1]} << 8 | std::uint32_t{pixel[2]} << 16;
}

}  // namespace surroundd
