#pragma once
// Bilinear sampling of camera frames at a LutTap's fixed-point position, in any PixelFormat a
// frame is held in: the one piece of pixel arithmetic that the stitcher and colour correction
// share. A YUV frame is interpolated in YUV (each of the four neighbours with the chroma its
// camera gave it, as cv::cvtColor would have given it) and only the result is converted to BGR:
// the conversion is affine but for its rounding and clamping, so this agrees with converting the
// whole frame first and sampling the BGR within a level or two, at one conversion per sample.

#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__ARM_NEON)
#include <arm_neon.h>
#endif

#include "common/pixel_format.hpp"
#include "processing/stitch/kernel_path.hpp"
#include "processing/stitch/panorama_lut.hpp"

namespace surroundd::processing {

// ceil(2^64 / width): what rowOf() multiplies by (0 for no width).
constexpr std::uint64_t rowReciprocalOf(std::uint32_t width) {
  return width == 0 ? 0 : ~std::uint64_t{0} / width + 1;
}

// A camera frame as the kernels read it. Taps address pixels as row * width + column, so the
// frame must be continuous (holds() in common/pixel_format.hpp).
struct SampledImage {
  const std::uint8_t* pixels = nullptr;  // BGR, YUYV or UYVY pixels, or NV12's luma plane
  const std::uint8_t* chroma = nullptr;  // NV12: the Cb Cr plane
  std::size_t rowBytes = 0;              // of `pixels`
  std::uint32_t width = 0;
  // NV12: ceil(2^64 / width), to find a tap's row without a division (rowOf()).
  std::uint64_t rowReciprocal = 0;
  PixelFormat format = PixelFormat::kBgr;

  // `held` must hold a picture in `format` (common/pixel_format.hpp) and outlive the result.
  static SampledImage of(const cv::Mat& held, PixelFormat format) {
    const cv::Size size = pictureSize(format, held);
    SampledImage image;
    image.pixels = held.ptr<std::uint8_t>();
    image.rowBytes = held.step;
    image.width = static_cast<std::uint32_t>(size.width);
    image.format = format;
    if (format == PixelFormat::kNv12) {
      image.rowReciprocal = rowReciprocalOf(image.width);
      image.chroma = held.ptr<std::uint8_t>(size.height);
    }
    return image;
  }
};

// The 2x2 neighbourhood of a tap, each pixel as c0 | c1 << 8 | c2 << 16 (B G R, or Y Cb Cr); the
// top byte is whatever the loader found there and is never part of a result.
struct Neighbours {
  std::uint32_t topLeft;
  std::uint32_t topRight;
  std::uint32_t bottomLeft;
  std::uint32_t bottomRight;
};

// The bytes of pixel `column` (0 or 1) of the two BGR pixels at p, plus the next pixel's c0 << 24
// for column 0: four bytes read from inside the two pixels' six, so that the last pixel of an
// image is safe to read.
inline std::uint32_t pixelBytes(const std::uint8_t* p, int column) {
  std::uint32_t bytes = 0;
  std::memcpy(&bytes, p + 2 * column, 4);
  return column == 0 ? bytes : bytes >> 8;
}

// Bytes per pixel of a frame's first plane (NV12: its luma).
template <PixelFormat kFormat>
inline constexpr bool kPacked422 = kFormat == PixelFormat::kYuyv || kFormat == PixelFormat::kUyvy;
template <PixelFormat kFormat>
inline constexpr std::size_t kFirstPlaneBytes = kFormat == PixelFormat::kBgr ? 3
                                                : kPacked422<kFormat>        ? 2
                                                                             : 1;

// Where a tap's top-left pixel starts in the frame's first plane: to prefetch it.
template <PixelFormat kFormat>
inline const std::uint8_t* firstByte(const SampledImage& image, std::uint32_t offset) {
  return image.pixels + static_cast<std::size_t>(offset) * kFirstPlaneBytes<kFormat>;
}

// The row of the pixel at `offset`, without a division: offset * ceil(2^64 / width) / 2^64 exceeds
// offset / width by less than offset / 2^64 < 2^-32, less than the 1 / width that a fraction of
// offset / width stays below 1 by, so the floor is the row for any offset and width.
inline std::uint32_t rowOf(const SampledImage& image, std::uint32_t offset) {
  __extension__ using Wide = unsigned __int128;
  return static_cast<std::uint32_t>((Wide{offset} * image.rowReciprocal) >> 64);
}

template <PixelFormat kFormat>
inline Neighbours neighbours(const SampledImage& image, std::uint32_t offset) {
  if constexpr (kFormat == PixelFormat::kBgr) {
    const std::uint8_t* top = image.pixels + static_cast<std::size_t>(offset) * 3;
    const std::uint8_t* bottom = top + image.rowBytes;
    return {pixelBytes(top, 0), pixelBytes(top, 1), pixelBytes(bottom, 0), pixelBytes(bottom, 1)};
  } else if constexpr (kPacked422<kFormat>) {
    // Y0 Cb Y1 Cr (YUYV) or Cb Y0 Cr Y1 (UYVY): each pixel's pair read whole (the left pixel's,
    // then the right one's: the same pair for an even offset, the next for an odd one), its Y
    // picked by the offset's parity. The width is even, so a pixel's column has the parity of
    // its offset.
    const std::uint32_t odd = offset & 1U;
    const std::uint8_t* base = image.pixels + static_cast<std::size_t>(offset & ~1U) * 2;
    const std::size_t next = 4 * odd;
    const auto pixel = [](const std::uint8_t* pair, std::uint32_t lumaShift) {
      std::uint32_t bytes = 0;
      std::memcpy(&bytes, pair, 4);
      if constexpr (kFormat == PixelFormat::kYuyv) {
        return ((bytes >> lumaShift) & 0xffU) | (bytes & 0xff00U) | ((bytes >> 8) & 0xff0000U);
      } else {
        return ((bytes >> (lumaShift + 8)) & 0xffU) | ((bytes & 0xffU) << 8) | (bytes & 0xff0000U);
      }
    };
    const std::uint32_t leftShift = 16 * odd;
    const std::uint32_t rightShift = 16 - leftShift;
    const std::uint8_t* bottom = base + image.rowBytes;
    return {pixel(base, leftShift), pixel(base + next, rightShift), pixel(bottom, leftShift),
            pixel(bottom + next, rightShift)};
  } else {
    const std::uint32_t y = rowOf(image, offset);
    const std::uint32_t x = offset - y * image.width;
    const std::uint8_t* luma = image.pixels + offset;
    const std::size_t pairColumn = x & ~1U;
    const std::size_t next = 2 * (x & 1U);  // the right pixel's pair, from the left one's
    const std::uint8_t* upper = image.chroma + (y >> 1) * static_cast<std::size_t>(image.width);
    const std::uint8_t* lower =
        image.chroma + ((y + 1) >> 1) * static_cast<std::size_t>(image.width);
    const auto pixel = [](std::uint8_t level, const std::uint8_t* pair) {
      return level | std::uint32_t{pair[0]} << 8 | std::uint32_t{pair[1]} << 16;
    };
    return {pixel(luma[0], upper + pairColumn), pixel(luma[1], upper + pairColumn + next),
            pixel(luma[image.rowBytes], lower + pairColumn),
            pixel(luma[image.rowBytes + 1], lower + pairColumn + next)};
  }
}

// Bilinear interpolation of the neighbours in fixed point (weights in 1/128, result rounded), as
// the bytes c0 | c1 << 8 | c2 << 16. Horizontal first in 16 bits (at most 255 * 128), then
// vertical in 32; every path computes exactly what the portable one does (kernel_path.hpp).
template <KernelPath kPath = kNativeKernels>
inline std::uint32_t interpolate(const Neighbours& n, const LutTap& tap) {
  static_assert(kernelPathBuilt(kPath), "this build has no such kernels");
  const int wx1 = tap.fx;
  const int wx0 = LutTap::kFractionOne - wx1;
  const int wy1 = tap.fy;
  const int wy0 = LutTap::kFractionOne - wy1;
#if defined(__SSE2__)
  if constexpr (kPath == KernelPath::kSse2) {
    const __m128i zero = _mm_setzero_si128();
    const __m128i weightLeft = _mm_set1_epi16(static_cast<short>(wx0));
    const __m128i weightRight = _mm_set1_epi16(static_cast<short>(wx1));
    const auto horizontal = [&](std::uint32_t left, std::uint32_t right) {
      const auto l = _mm_unpacklo_epi8(_mm_cvtsi32_si128(static_cast<int>(left)), zero);
      const auto r = _mm_unpacklo_epi8(_mm_cvtsi32_si128(static_cast<int>(right)), zero);
      return _mm_add_epi16(_mm_mullo_epi16(l, weightLeft), _mm_mullo_epi16(r, weightRight));
    };
    const __m128i pairs = _mm_unpacklo_epi16(horizontal(n.topLeft, n.topRight),
                                             horizontal(n.bottomLeft, n.bottomRight));
    __m128i sum = _mm_madd_epi16(pairs, _mm_set1_epi32(wy0 | (wy1 << 16)));
    sum = _mm_srli_epi32(_mm_add_epi32(sum, _mm_set1_epi32(1 << 13)), 14);
    sum = _mm_packs_epi32(sum, sum);
    return static_cast<std::uint32_t>(_mm_cvtsi128_si32(_mm_packus_epi16(sum, sum))) & 0xffffffU;
  }
#elif defined(__ARM_NEON)
  if constexpr (kPath == KernelPath::kNeon) {
    // c0 c1 c2 (and the top byte) of the left and the right pixel of a row, in 16-bit lanes.
    const auto horizontal = [&](std::uint32_t left, std::uint32_t right) {
      const uint16x4_t l = vget_low_u16(vmovl_u8(vcreate_u8(left)));
      const uint16x4_t r = vget_low_u16(vmovl_u8(vcreate_u8(right)));
      return vmla_n_u16(vmul_n_u16(l, static_cast<std::uint16_t>(wx0)), r,
                        static_cast<std::uint16_t>(wx1));
    };
    uint32x4_t sum =
        vmull_n_u16(horizontal(n.topLeft, n.topRight), static_cast<std::uint16_t>(wy0));
    sum =
        vmlal_n_u16(sum, horizontal(n.bottomLeft, n.bottomRight), static_cast<std::uint16_t>(wy1));
    // Rounded: (sum + 2^13) >> 14, at most 255, so the narrowing moves lose nothing.
    const uint8x8_t bytes = vmovn_u16(vcombine_u16(vrshrn_n_u32(sum, 14), vdup_n_u16(0)));
    return vget_lane_u32(vreinterpret_u32_u8(bytes), 0) & 0xffffffU;
  }
#endif
  std::uint32_t packed = 0;
  for (int c = 0; c < 3; ++c) {
    const auto level = [c](std::uint32_t pixel) {
      return static_cast<int>((pixel >> (8 * c)) & 0xffU);
    };
    const int upper = level(n.topLeft) * wx0 + level(n.topRight) * wx1;
    const int lower = level(n.bottomLeft) * wx0 + level(n.bottomRight) * wx1;
    packed |= static_cast<std::uint32_t>((upper * wy0 + lower * wy1 + (1 << 13)) >> 14) << (8 * c);
  }
  return packed;
}

// An interpolated pixel of a frame in kFormat, as B | G << 8 | R << 16.
template <PixelFormat kFormat>
inline std::uint32_t toBgr(std::uint32_t interpolated) {
  if constexpr (kFormat == PixelFormat::kBgr) {
    return interpolated;
  } else {
    return yuvToBgr(interpolated);
  }
}

// One bilinear sample of `image` at `tap`, as B | G << 8 | R << 16. Reads stay inside the 2x2
// neighbourhood's bytes (and, for YUV, the chroma those pixels share), so the last pixel of a
// frame is safe to sample.
template <PixelFormat kFormat, KernelPath kPath = kNativeKernels>
inline std::uint32_t bilinear(const SampledImage& image, const LutTap& tap) {
  return toBgr<kFormat>(interpolate<kPath>(neighbours<kFormat>(image, tap.offset), tap));
}

// The same for a format known only at run time (colour correction's seam samples: a few thousand
// per frame, where the branch costs nothing).
inline std::uint32_t bilinear(const SampledImage& image, const LutTap& tap) {
  switch (image.format) {
    case PixelFormat::kYuyv:
      return bilinear<PixelFormat::kYuyv>(image, tap);
    case PixelFormat::kUyvy:
      return bilinear<PixelFormat::kUyvy>(image, tap);
    case PixelFormat::kNv12:
      return bilinear<PixelFormat::kNv12>(image, tap);
    case PixelFormat::kBgr:
      break;
  }
  return bilinear<PixelFormat::kBgr>(image, tap);
}

}  // namespace surroundd::processing
