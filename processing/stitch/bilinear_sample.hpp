#pragma once
// Bilinear sampling of 8-bit 3-channel images at a LutTap's fixed-point position: the one piece
// of pixel arithmetic that the stitcher and colour correction share.

#include <cstdint>
#include <cstring>

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__ARM_NEON)
#include <arm_neon.h>
#endif

#include "processing/stitch/kernel_path.hpp"
#include "processing/stitch/panorama_lut.hpp"

namespace surroundd::processing {

// The bytes of pixel `column` (0 or 1) of the two at p, as c0 | c1 << 8 | c2 << 16, plus the next
// pixel's c0 << 24 for column 0: four bytes read from inside the two pixels' six, so that the
// last pixel of an image is safe to read.
inline std::uint32_t pixelBytes(const std::uint8_t* p, int column) {
  std::uint32_t bytes = 0;
  std::memcpy(&bytes, p + 2 * column, 4);
  return column == 0 ? bytes : bytes >> 8;
}

// Bilinear sample of one 3-byte pixel in fixed point (weights in 1/128, result rounded), as the
// bytes c0 | c1 << 8 | c2 << 16. Horizontal first in 16 bits (at most 255 * 128), then vertical in
// 32; every path computes exactly what the portable one does (kernel_path.hpp). Reads stay inside
// the 2x2 neighbourhood's bytes, so the last pixel of an image is safe to sample.
template <KernelPath kPath = kNativeKernels>
inline std::uint32_t bilinear(const std::uint8_t* source, std::size_t rowBytes, const LutTap& tap) {
  static_assert(kernelPathBuilt(kPath), "this build has no such kernels");
  const std::uint8_t* top = source + static_cast<std::size_t>(tap.offset) * 3;
  const std::uint8_t* bottom = top + rowBytes;
  const int wx1 = tap.fx;
  const int wx0 = LutTap::kFractionOne - wx1;
  const int wy1 = tap.fy;
  const int wy0 = LutTap::kFractionOne - wy1;
#if defined(__SSE2__)
  if constexpr (kPath == KernelPath::kSse2) {
    const __m128i zero = _mm_setzero_si128();
    const __m128i weightLeft = _mm_set1_epi16(static_cast<short>(wx0));
    const __m128i weightRight = _mm_set1_epi16(static_cast<short>(wx1));
    const auto horizontal = [&](const std::uint8_t* p) {
      const auto l = _mm_unpacklo_epi8(_mm_cvtsi32_si128(static_cast<int>(pixelBytes(p, 0))), zero);
      const auto r = _mm_unpacklo_epi8(_mm_cvtsi32_si128(static_cast<int>(pixelBytes(p, 1))), zero);
      return _mm_add_epi16(_mm_mullo_epi16(l, weightLeft), _mm_mullo_epi16(r, weightRight));
    };
    const __m128i pairs = _mm_unpacklo_epi16(horizontal(top), horizontal(bottom));
    __m128i sum = _mm_madd_epi16(pairs, _mm_set1_epi32(wy0 | (wy1 << 16)));
    sum = _mm_srli_epi32(_mm_add_epi32(sum, _mm_set1_epi32(1 << 13)), 14);
    sum = _mm_packs_epi32(sum, sum);
    return static_cast<std::uint32_t>(_mm_cvtsi128_si32(_mm_packus_epi16(sum, sum))) & 0xffffffU;
  }
#elif defined(__ARM_NEON)
  if constexpr (kPath == KernelPath::kNeon) {
    // c0 c1 c2 (and one more byte) of the left and the right pixel of a row, in 16-bit lanes.
    const auto horizontal = [&](const std::uint8_t* p) {
      const uint16x4_t l = vget_low_u16(vmovl_u8(vcreate_u8(pixelBytes(p, 0))));
      const uint16x4_t r = vget_low_u16(vmovl_u8(vcreate_u8(pixelBytes(p, 1))));
      return vmla_n_u16(vmul_n_u16(l, static_cast<std::uint16_t>(wx0)), r,
                        static_cast<std::uint16_t>(wx1));
    };
    uint32x4_t sum = vmull_n_u16(horizontal(top), static_cast<std::uint16_t>(wy0));
    sum = vmlal_n_u16(sum, horizontal(bottom), static_cast<std::uint16_t>(wy1));
    // Rounded: (sum + 2^13) >> 14, at most 255, so the narrowing moves lose nothing.
    const uint8x8_t bytes = vmovn_u16(vcombine_u16(vrshrn_n_u32(sum, 14), vdup_n_u16(0)));
    return vget_lane_u32(vreinterpret_u32_u8(bytes), 0) & 0xffffffU;
  }
#endif
  std::uint32_t packed = 0;
  for (int c = 0; c < 3; ++c) {
    const int upper = top[c] * wx0 + top[3 + c] * wx1;
    const int lower = bottom[c] * wx0 + bottom[3 + c] * wx1;
    packed |= static_cast<std::uint32_t>((upper * wy0 + lower * wy1 + (1 << 13)) >> 14) << (8 * c);
  }
  return packed;
}

}  // namespace surroundd::processing
