#include "processing/stitch/stitcher.hpp"

#include <array>
#include <cstring>
#include <stdexcept>

#if defined(__SSE2__)
#include <emmintrin.h>
#elif defined(__ARM_NEON)
#include <arm_neon.h>
#endif

#include <fmt/format.h>

#include "common/work_pool.hpp"
#include "processing/stitch/bilinear_sample.hpp"
#include "processing/stitch/yuv_lanes.hpp"

namespace surroundd::processing {
namespace {

#if defined(__SSE2__)
// Two pixels at once, the same arithmetic as interpolate() in eight 16-bit lanes: half the
// instructions per pixel; a YUV frame's are converted to BGR in the same lanes (yuv_lanes.hpp).
// kPairPath names the kernel path it serves. Returns pixel a in the low 32 bits and b in the high
// 32 (each B G R 0).
template <PixelFormat kFormat>
[[gnu::always_inline]] inline std::uint64_t interpolatePair(const Neighbours& na, const LutTap& a,
                                                            const Neighbours& nb, const LutTap& b) {
  const __m128i zero = _mm_setzero_si128();
  // Two pixels of both neighbourhoods, 16-bit lanes: a's in 0-3, b's in 4-7.
  const auto lanes = [&](std::uint32_t pa, std::uint32_t pb) {
    return _mm_unpacklo_epi8(_mm_unpacklo_epi32(_mm_cvtsi32_si128(static_cast<int>(pa)),
                                                _mm_cvtsi32_si128(static_cast<int>(pb))),
                             zero);
  };
  const __m128i wx1 = _mm_unpacklo_epi64(_mm_set1_epi16(static_cast<short>(a.fx)),
                                         _mm_set1_epi16(static_cast<short>(b.fx)));
  const __m128i wx0 = _mm_sub_epi16(_mm_set1_epi16(LutTap::kFractionOne), wx1);
  const __m128i upper = _mm_add_epi16(_mm_mullo_epi16(lanes(na.topLeft, nb.topLeft), wx0),
                                      _mm_mullo_epi16(lanes(na.topRight, nb.topRight), wx1));
  const __m128i lower = _mm_add_epi16(_mm_mullo_epi16(lanes(na.bottomLeft, nb.bottomLeft), wx0),
                                      _mm_mullo_epi16(lanes(na.bottomRight, nb.bottomRight), wx1));
  const auto vertical = [](__m128i pairs, const LutTap& tap) {
    const int wy1 = tap.fy;
    const int wy0 = LutTap::kFractionOne - wy1;
    const __m128i sum = _mm_madd_epi16(pairs, _mm_set1_epi32(wy0 | (wy1 << 16)));
    return _mm_srli_epi32(_mm_add_epi32(sum, _mm_set1_epi32(1 << 13)), 14);
  };
  const __m128i resultA = vertical(_mm_unpacklo_epi16(upper, lower), a);
  const __m128i resultB = vertical(_mm_unpackhi_epi16(upper, lower), b);
  __m128i words = _mm_packs_epi32(resultA, resultB);
  if constexpr (kFormat != PixelFormat::kBgr) words = yuvToBgrLanes(words);
  const __m128i bytes = _mm_packus_epi16(words, words);
  return static_cast<std::uint64_t>(_mm_cvtsi128_si64(bytes)) & 0x00ffffff00ffffffULL;
}
constexpr KernelPath kPairPath = KernelPath::kSse2;
#elif defined(__ARM_NEON)
// The same two pixels at once in NEON's eight 16-bit lanes, a's in 0-3 and b's in 4-7.
template <PixelFormat kFormat>
[[gnu::always_inline]] inline std::uint64_t interpolatePair(const Neighbours& na, const LutTap& a,
                                                            const Neighbours& nb, const LutTap& b) {
  const auto lanes = [](std::uint32_t pa, std::uint32_t pb) {
    return vmovl_u8(vcreate_u8(pa | std::uint64_t{pb} << 32));
  };
  const uint16x8_t wx1 = vcombine_u16(vdup_n_u16(static_cast<std::uint16_t>(a.fx)),
                                      vdup_n_u16(static_cast<std::uint16_t>(b.fx)));
  const uint16x8_t wx0 = vsubq_u16(vdupq_n_u16(LutTap::kFractionOne), wx1);
  const uint16x8_t upper = vmlaq_u16(vmulq_u16(lanes(na.topLeft, nb.topLeft), wx0),
                                     lanes(na.topRight, nb.topRight), wx1);
  const uint16x8_t lower = vmlaq_u16(vmulq_u16(lanes(na.bottomLeft, nb.bottomLeft), wx0),
                                     lanes(na.bottomRight, nb.bottomRight), wx1);
  const auto vertical = [](uint16x4_t up, uint16x4_t low, const LutTap& tap) {
    const auto wy1 = static_cast<std::uint16_t>(tap.fy);
    const auto wy0 = static_cast<std::uint16_t>(LutTap::kFractionOne - wy1);
    return vrshrn_n_u32(vmlal_n_u16(vmull_n_u16(up, wy0), low, wy1), 14);  // (sum + 2^13) >> 14
  };
  const uint16x8_t words = vcombine_u16(vertical(vget_low_u16(upper), vget_low_u16(lower), a),
                                        vertical(vget_high_u16(upper), vget_high_u16(lower), b));
  uint8x8_t bytes;
  if constexpr (kFormat == PixelFormat::kBgr) {
    bytes = vmovn_u16(words);
  } else {
    bytes = vqmovun_s16(yuvToBgrLanes(words));
  }
  return vget_lane_u64(vreinterpret_u64_u8(bytes), 0) & 0x00ffffff00ffffffULL;
}
constexpr KernelPath kPairPath = KernelPath::kNeon;
#endif

constexpr int kPrefetchAhead = 64;  // pixels

}  // namespace

Stitcher::Stitcher(const PanoramaLut& lut, WorkPool& pool)
    : lut_(lut),
      pool_(pool),
      unseen_{blackPicture(PixelFormat::kBgr, {2, 2}), blackPicture(PixelFormat::kYuyv, {2, 2}),
              blackPicture(PixelFormat::kNv12, {2, 2}), blackPicture(PixelFormat::kUyvy, {2, 2})} {
  // Per row, the columns from the first to the last pixel a camera sees; outside them the row is
  // filled, not sampled (a quarter of the paper rig's panorama is above every camera's view).
  seenSpans_.reserve(static_cast<std::size_t>(lut_.size.height));
  for (int v = 0; v < lut_.size.height; ++v) {
    const LutTap* taps = lut_.taps.data() + static_cast<std::size_t>(v) * lut_.size.width;
    int begin = 0;
    int end = lut_.size.width;
    while (begin < end && taps[begin].camera == PanoramaLut::kUnseen) ++begin;
    while (end > begin && taps[end - 1].camera == PanoramaLut::kUnseen) --end;
    seenSpans_.push_back(begin < end ? std::pair{begin, end} : std::pair{0, 0});
  }
}

void Stitcher::stitch(std::span<const cv::Mat> frames, PixelFormat format, cv::Mat& panorama,
                      KernelPath path) {
  if (!kernelPathBuilt(path)) {
    throw std::invalid_argument(
        fmt::format("stitch: this build has no {} kernels", kernelPathName(path)));
  }
  if (frames.size() != lut_.cameraSizes.size()) {
    throw std::invalid_argument(fmt::format("stitch: {} frames for a LUT of {} cameras",
                                            frames.size(), lut_.cameraSizes.size()));
  }
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (!holds(frames[i], format, lut_.cameraSizes[i])) {
      throw std::invalid_argument(
          fmt::format("stitch: frame {} is not a continuous {} picture of {}x{}", i,
                      toString(format), lut_.cameraSizes[i].width, lut_.cameraSizes[i].height));
    }
    images_[i] = SampledImage::of(frames[i], format);
  }
  images_[PanoramaLut::kUnseen] =
      SampledImage::of(unseen_[static_cast<std::size_t>(format)], format);
  panorama.create(lut_.size, CV_8UC3);
  // Chunks of rows, several per thread: rows cost unevenly (blend bands, memory locality).
  const auto rows = rowsFor(path, format);
  pool_.parallelFor(
      lut_.size.height, [&](int first, int last) { (this->*rows)(first, last, panorama); },
      pool_.threads() * 8);
}

template <KernelPath kPath>
Stitcher::RowKernel Stitcher::rowsOf(PixelFormat format) {
  switch (format) {
    case PixelFormat::kYuyv:
      return &Stitcher::stitchRows<kPath, PixelFormat::kYuyv>;
    case PixelFormat::kUyvy:
      return &Stitcher::stitchRows<kPath, PixelFormat::kUyvy>;
    case PixelFormat::kNv12:
      return &Stitcher::stitchRows<kPath, PixelFormat::kNv12>;
    case PixelFormat::kBgr:
      break;
  }
  return &Stitcher::stitchRows<kPath, PixelFormat::kBgr>;
}

Stitcher::RowKernel Stitcher::rowsFor(KernelPath path, PixelFormat format) {
  return path == kNativeKernels ? rowsOf<kNativeKernels>(format)
                                : rowsOf<KernelPath::kPortable>(format);
}

template <KernelPath kPath, PixelFormat kFormat>
void Stitcher::stitchRows(int first, int last, cv::Mat& panorama) const {
  // A local copy, not the member: stores through the byte pointer `row` could alias any member,
  // which would make the compiler reload them for every pixel.
  const auto images = images_;
  const auto sample = [&images](const LutTap& tap) {
    return bilinear<kFormat, kPath>(images[tap.camera], tap);
  };
  const int width = lut_.size.width;
  const std::array<std::uint8_t, 3> unseen = {
      PanoramaLut::kUnseenColour[0], PanoramaLut::kUnseenColour[1], PanoramaLut::kUnseenColour[2]};
  for (int v = first; v < last; ++v) {
    auto* row = panorama.ptr<std::uint8_t>(v);
    const auto out = [row](int x) { return row + static_cast<std::size_t>(x) * 3; };
    const LutTap* taps = lut_.taps.data() + static_cast<std::size_t>(v) * width;
    const auto [begin, end] = seenSpans_[static_cast<std::size_t>(v)];
    // Four-byte stores: a pixel's fourth byte lands on the next pixel, which is written after it
    // (by the kernel or the unseen fill below); only the row's last pixel is stored in 3 bytes.
    const int spillEnd = end == width ? width - 1 : end;
    int u = begin;
#if defined(__SSE2__) || defined(__ARM_NEON)
    if constexpr (kPath == kPairPath) {
      for (; u + 2 <= spillEnd; u += 2) {
        // The source pixels of a panorama row lie along a curve through the camera image that the
        // hardware prefetcher does not follow: ask for them ahead (measured: a third faster at
        // 1080p; per pixel beats once per cache line, which needs a branch or misses lines).
        for (int k = 0; k < 2; ++k) {
          if (u + k + kPrefetchAhead < end) {
            const LutTap ahead = taps[u + k + kPrefetchAhead];
            const SampledImage& image = images[ahead.camera];
            const std::uint8_t* at = firstByte<kFormat>(image, ahead.offset);
            __builtin_prefetch(at);
            __builtin_prefetch(at + image.rowBytes);
          }
        }
        const LutTap a = taps[u];
        const LutTap b = taps[u + 1];
        const std::uint64_t pair =
            interpolatePair<kFormat>(neighbours<kFormat>(images[a.camera], a.offset), a,
                                     neighbours<kFormat>(images[b.camera], b.offset), b);
        const auto left = static_cast<std::uint32_t>(pair);
        const auto right = static_cast<std::uint32_t>(pair >> 32);
        std::memcpy(out(u), &left, 4);
        std::memcpy(out(u + 1), &right, 4);
      }
    }
#endif
    for (; u < spillEnd; ++u) {
      const std::uint32_t value = sample(taps[u]);
      std::memcpy(out(u), &value, 4);
    }
    if (end == width && begin < end) {
      const std::uint32_t value = sample(taps[width - 1]);
      std::memcpy(out(width - 1), &value, 3);
    }
    // What no camera sees, on either side of the span (whole rows above the cameras' view).
    for (int x = 0; x < begin; ++x) std::memcpy(out(x), unseen.data(), 3);
    for (int x = end; x < width; ++x) std::memcpy(out(x), unseen.data(), 3);

    const std::size_t rowFirstPixel = static_cast<std::size_t>(v) * width;
    for (std::uint32_t b = lut_.blendRowBegin[v]; b < lut_.blendRowBegin[v + 1]; ++b) {
      const BlendTap& blend = lut_.blendTaps[b];
      const std::uint32_t other = sample(blend.tap);
      std::uint8_t* pixel = out(static_cast<int>(blend.pixel - rowFirstPixel));
      const std::uint32_t w = blend.tap.weight;
      for (int c = 0; c < 3; ++c) {
        const std::uint32_t mine = pixel[c];
        const std::uint32_t theirs = (other >> (8 * c)) & 0xffU;
        pixel[c] = static_cast<std::uint8_t>((mine * (256 - w) + theirs * w + 128) >> 8);
      }
    }
  }
}

}  // namespace surroundd::processing
