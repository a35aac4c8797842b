#pragma once
// Two interpolated YUV pixels to BGR at once in SIMD lanes, bit for bit as bt601::yuvToBgr()
// converts each: the stitcher's gather converts every pixel it samples from a YUV frame, and one
// scalar conversion per pixel cost as much as the sampling itself (measured: a YUYV stitch took
// 2.5x a BGR one). Lanes in and out: pixel a's Y Cb Cr (B G R) in 16-bit lanes 0-2, pixel b's in
// 4-6; lanes 3 and 7 are ignored on the way in and 0 on the way out. The results are not yet
// clamped: the caller's saturating pack to bytes does that, as yuvToBgr() clamps.

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__ARM_NEON)
#include <arm_neon.h>
#endif

#include "common/bt601.hpp"

namespace surroundd::processing {

#if defined(__SSE2__)
namespace yuv_lanes {
// SSE2 multiplies 16-bit lanes only (_mm_madd_epi16: two products summed into 32 bits), so each
// 20-bit constant is split as high * 128 + low, both within 16 bits: the sum of the two products
// is the constant's product exactly.
constexpr short high(int constant) {
  return static_cast<short>(constant >= 0 ? constant / 128 : -((-constant + 127) / 128));
}
constexpr short low(int constant) { return static_cast<short>(constant - high(constant) * 128); }
}  // namespace yuv_lanes

[[gnu::always_inline]] inline __m128i yuvToBgrLanes(__m128i yuv) {
  using namespace bt601;
  using yuv_lanes::high;
  using yuv_lanes::low;
  // Y - 16 (at least 0), Cb - 128, Cr - 128.
  const __m128i centred =
      _mm_max_epi16(_mm_sub_epi16(yuv, _mm_setr_epi16(16, 128, 128, 0, 16, 128, 128, 0)),
                    _mm_setr_epi16(0, -256, -256, -256, 0, -256, -256, -256));
  // Per output lane B G R -: the (Y, Cb) pair's weights and the (Cr, -) pair's.
  const __m128i lumaCbHigh = _mm_setr_epi16(high(kLuma), high(kCbToBlue), high(kLuma),
                                            high(kCbToGreen), high(kLuma), 0, 0, 0);
  const __m128i lumaCbLow =
      _mm_setr_epi16(low(kLuma), low(kCbToBlue), low(kLuma), low(kCbToGreen), low(kLuma), 0, 0, 0);
  const __m128i crHigh = _mm_setr_epi16(0, 0, high(kCrToGreen), 0, high(kCrToRed), 0, 0, 0);
  const __m128i crLow = _mm_setr_epi16(0, 0, low(kCrToGreen), 0, low(kCrToRed), 0, 0, 0);
  const auto convert = [&](__m128i lumaCb, __m128i cr) {
    const __m128i highSum =
        _mm_add_epi32(_mm_madd_epi16(lumaCb, lumaCbHigh), _mm_madd_epi16(cr, crHigh));
    const __m128i lowSum =
        _mm_add_epi32(_mm_madd_epi16(lumaCb, lumaCbLow), _mm_madd_epi16(cr, crLow));
    const __m128i sum =
        _mm_add_epi32(_mm_add_epi32(_mm_slli_epi32(highSum, 7), lowSum), _mm_set1_epi32(kHalf));
    return _mm_srai_epi32(sum, kShift);
  };
  // Each pixel's (Y, Cb) and (Cr, -) pairs repeated into all four 32-bit lanes.
  const __m128i a = convert(_mm_shuffle_epi32(centred, _MM_SHUFFLE(0, 0, 0, 0)),
                            _mm_shuffle_epi32(centred, _MM_SHUFFLE(1, 1, 1, 1)));
  const __m128i b = convert(_mm_shuffle_epi32(centred, _MM_SHUFFLE(2, 2, 2, 2)),
                            _mm_shuffle_epi32(centred, _MM_SHUFFLE(3, 3, 3, 3)));
  return _mm_packs_epi32(a, b);
}
#elif defined(__ARM_NEON)
[[gnu::always_inline]] inline int16x8_t yuvToBgrLanes(uint16x8_t yuv) {
  using namespace bt601;
  // Y - 16 (at least 0), Cb - 128, Cr - 128.
  const int16x8_t offsets = {16, 128, 128, 0, 16, 128, 128, 0};
  const int16x8_t floors = {0, -256, -256, -256, 0, -256, -256, -256};
  const int16x8_t centred = vmaxq_s16(vsubq_s16(vreinterpretq_s16_u16(yuv), offsets), floors);
  const int32x4_t luma = {kLuma, kLuma, kLuma, 0};
  const int32x4_t cb = {kCbToBlue, kCbToGreen, 0, 0};
  const int32x4_t cr = {0, kCrToGreen, kCrToRed, 0};
  const auto convert = [&](int16x4_t pixel) {
    const int32x4_t levels = vmovl_s16(pixel);
    int32x4_t sum = vmlaq_n_s32(vdupq_n_s32(kHalf), luma, vgetq_lane_s32(levels, 0));
    sum = vmlaq_n_s32(sum, cb, vgetq_lane_s32(levels, 1));
    sum = vmlaq_n_s32(sum, cr, vgetq_lane_s32(levels, 2));
    return vqmovn_s32(vshrq_n_s32(sum, kShift));
  };
  return vcombine_s16(convert(vget_low_s16(centred)), convert(vget_high_s16(centred)));
}
#endif

}  // namespace surroundd::processing
