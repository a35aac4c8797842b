#pragma once
// BT.601 limited-range YUV to BGR, exactly as cv::cvtColor's YUV2BGR_YUYV and YUV2BGR_NV12 convert
// each pixel: 20-bit fixed point, luma 16..235 and chroma 16..240 around 128, as V4L2 cameras
// deliver it. Kept apart from OpenCV's headers so that the kernels built on it (the stitcher's
// SIMD lanes) can be checked alone under emulation.

#include <algorithm>
#include <cstdint>

namespace surroundd::bt601 {

inline constexpr int kShift = 20;
inline constexpr int kLuma = 1220542;       // 1.164 * 2^20
inline constexpr int kCbToBlue = 2116026;   // 2.018
inline constexpr int kCbToGreen = -409993;  // -0.391
inline constexpr int kCrToGreen = -852492;  // -0.813
inline constexpr int kCrToRed = 1673527;    // 1.596
inline constexpr int kHalf = 1 << (kShift - 1);

// One pixel: Y | Cb << 8 | Cr << 16 to B | G << 8 | R << 16.
inline std::uint32_t yuvToBgr(std::uint32_t yuv) {
  const int luma = std::max(0, static_cast<int>(yuv & 0xffU) - 16) * kLuma;
  const int cb = static_cast<int>((yuv >> 8) & 0xffU) - 128;
  const int cr = static_cast<int>((yuv >> 16) & 0xffU) - 128;
  const auto level = [](int fixed) {
    return static_cast<std::uint32_t>(std::clamp(fixed >> kShift, 0, 255));
  };
  return level(luma + kHalf + kCbToBlue * cb) |
         level(luma + kHalf + kCbToGreen * cb + kCrToGreen * cr) << 8 |
         level(luma + kHalf + kCrToRed * cr) << 16;
}

}  // namespace surroundd::bt601
