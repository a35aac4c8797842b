#pragma once
// What V4L2Source negotiates with a device, kept apart from streaming: the pixel formats it can
// convert (and their fourccs, single- and multi-planar), and what a device offers, enumerated and
// described for the message when the settings cannot be met.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <linux/videodev2.h>
#include <opencv2/core.hpp>

#include "capture/pixel_conversion.hpp"
#include "capture/v4l2_device.hpp"
#include "capture/v4l2_source.hpp"

namespace surroundd::capture {

struct V4l2FormatCode {
  V4l2Format format;
  std::uint32_t fourcc;
  PixelLayout layout;
  std::uint32_t planes;  // buffers a frame comes in (multi-planar API only: NV12M has two)
};
// In the order `auto` tries them. NV12M (luma and chroma in two buffers) is only offered through
// the multi-planar API; the config calls both NV12 layouts "nv12".
inline constexpr std::array<V4l2FormatCode, 5> kV4l2Formats{{
    {V4l2Format::kYuyv, V4L2_PIX_FMT_YUYV, PixelLayout::kYuyv, 1},
    {V4l2Format::kUyvy, V4L2_PIX_FMT_UYVY, PixelLayout::kUyvy, 1},
    {V4l2Format::kNv12, V4L2_PIX_FMT_NV12, PixelLayout::kNv12, 1},
    {V4l2Format::kNv12, V4L2_PIX_FMT_NV12M, PixelLayout::kNv12, 2},
    {V4l2Format::kMjpeg, V4L2_PIX_FMT_MJPEG, PixelLayout::kMjpeg, 1},
}};

// One pixel format a device offers, with its sizes: "YUYV 640x480, 1280x720".
struct V4l2Offer {
  std::uint32_t fourcc = 0;
  std::vector<cv::Size> sizes;  // discrete sizes
  // Per discrete size, the frame rates it is offered at (frames per second), where they were
  // asked for (FrameRates::kListed) and the driver lists them (discrete intervals).
  std::vector<std::vector<double>> rates;
  bool anySize = false;        // stepwise or continuous ranges
  cv::Size smallest, largest;  // of a range
  bool has(cv::Size size) const;
};

// Whether the frame rates of each size are asked for and told: only a listing wants them, and a
// driver like vivid answers thousands of VIDIOC_ENUM_FRAMEINTERVALS for them, which a camera's
// every (re)opening would pay.
enum class FrameRates { kLeftOut, kListed };

// The formats and sizes the device offers for buffers of `bufferType` (single- or multi-planar
// capture), with each size's rates where `rates` says.
std::vector<V4l2Offer> offersOf(V4l2Device& device, std::uint32_t bufferType,
                                FrameRates rates = FrameRates::kLeftOut);
// "YUYV 640x480, 320x240; MJPG 1280x720", or "nothing"; with the rates listed, each size's after
// it: "YUYV 640x480 (30, 15 fps)".
std::string describe(const std::vector<V4l2Offer>& offers, FrameRates rates = FrameRates::kLeftOut);
std::string fourccText(std::uint32_t code);

}  // namespace surroundd::capture
