#include "processing/stitch/i420_picture.hpp"

#include <cstdint>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/core/hal/intrin.hpp>

#include "common/work_pool.hpp"

namespace surroundd::processing {
namespace {

// BT.601 limited range in 8-bit fixed point: Y from one pixel, Cb and Cr from the sums of a 2x2
// block's four (so the mean's rounding is in the same shift).
int lumaOf(int b, int g, int r) { return ((66 * r + 129 * g + 25 * b + 128) >> 8) + 16; }
int cbOfSums(int b, int g, int r) { return ((112 * b - 74 * g - 38 * r + 512) >> 10) + 128; }
int crOfSums(int b, int g, int r) { return ((-18 * b - 94 * g + 112 * r + 512) >> 10) + 128; }

struct Planes {
  std::uint8_t* lumaTop;
  std::uint8_t* lumaBottom;
  std::uint8_t* cb;
  std::uint8_t* cr;
};

// Columns [first, width) of a row pair, one 2x2 block at a time.
void convertBlocks(const std::uint8_t* top, const std::uint8_t* bottom, int first, int width,
                   const Planes& out) {
  for (int x = first; x < width; x += 2) {
    const std::uint8_t* a = top + std::ptrdiff_t{3} * x;
    const std::uint8_t* c = bottom + std::ptrdiff_t{3} * x;
    out.lumaTop[x] = static_cast<std::uint8_t>(lumaOf(a[0], a[1], a[2]));
    out.lumaTop[x + 1] = static_cast<std::uint8_t>(lumaOf(a[3], a[4], a[5]));
    out.lumaBottom[x] = static_cast<std::uint8_t>(lumaOf(c[0], c[1], c[2]));
    out.lumaBottom[x + 1] = static_cast<std::uint8_t>(lumaOf(c[3], c[4], c[5]));
    const int b = a[0] + a[3] + c[0] + c[3];
    const int g = a[1] + a[4] + c[1] + c[4];
    const int r = a[2] + a[5] + c[2] + c[5];
    out.cb[x / 2] = static_cast<std::uint8_t>(cbOfSums(b, g, r));
    out.cr[x / 2] = static_cast<std::uint8_t>(crOfSums(b, g, r));
  }
}

#if CV_SIMD128
constexpr int kVectorPixels = 16;

// Sixteen pixels of a row pair with OpenCV's 128-bit universal intrinsics (SSE2, NEON): the same
// integer arithmetic as convertBlocks(), lanes wide enough that nothing wraps or saturates before
// the final packing clamps what convertBlocks()'s casts would not need to.
int convertVectors(const std::uint8_t* top, const std::uint8_t* bottom, int width,
                   const Planes& out) {
  const cv::v_uint16x8 wr = cv::v_setall_u16(66);
  const cv::v_uint16x8 wg = cv::v_setall_u16(129);
  const cv::v_uint16x8 wb = cv::v_setall_u16(25);
  const cv::v_uint16x8 lumaRound = cv::v_setall_u16(128);
  const cv::v_uint16x8 lumaFloor = cv::v_setall_u16(16);
  const cv::v_int16x8 ones = cv::v_setall_s16(1);
  // Cb: 112 b - 74 g on (b, g) pairs plus -38 r + 512 on (r, 1) pairs; Cr likewise.
  const cv::v_int16x8 cbBlueGreen =
      cv::v_reinterpret_as_s16(cv::v_setall_u32(112U | 0xffb6U << 16));
  const cv::v_int16x8 cbRedRound = cv::v_reinterpret_as_s16(cv::v_setall_u32(0xffdaU | 512U << 16));
  const cv::v_int16x8 crBlueGreen =
      cv::v_reinterpret_as_s16(cv::v_setall_u32(0xffeeU | 0xffa2U << 16));
  const cv::v_int16x8 crRedRound = cv::v_reinterpret_as_s16(cv::v_setall_u32(112U | 512U << 16));
  const cv::v_int32x4 chromaCentre = cv::v_setall_s32(128);
  const cv::v_uint32x4 lowWord = cv::v_setall_u32(0xffffU);

  const auto luma = [&](const cv::v_uint8x16& b, const cv::v_uint8x16& g, const cv::v_uint8x16& r,
                        std::uint8_t* into) {
    cv::v_uint16x8 b0, b1, g0, g1, r0, r1;
    cv::v_expand(b, b0, b1);
    cv::v_expand(g, g0, g1);
    cv::v_expand(r, r0, r1);
    const auto half = [&](const cv::v_uint16x8& bh, const cv::v_uint16x8& gh,
                          const cv::v_uint16x8& rh) {
      const cv::v_uint16x8 sum =
          cv::v_mul_wrap(rh, wr) + cv::v_mul_wrap(gh, wg) + cv::v_mul_wrap(bh, wb) + lumaRound;
      return cv::v_shr<8>(sum) + lumaFloor;
    };
    cv::v_store(into, cv::v_pack(half(b0, g0, r0), half(b1, g1, r1)));
  };
  // The sums of each 2x2 block of 16 columns of two rows: 8 sums, as 16-bit lanes.
  const auto blockSums = [&](const cv::v_uint8x16& upper, const cv::v_uint8x16& lower) {
    cv::v_uint16x8 u0, u1, l0, l1;
    cv::v_expand(upper, u0, u1);
    cv::v_expand(lower, l0, l1);
    const auto pairs = [&](const cv::v_uint16x8& columns) {
      const cv::v_uint32x4 both = cv::v_reinterpret_as_u32(columns);
      return (both & lowWord) + cv::v_shr<16>(both);
    };
    return cv::v_reinterpret_as_s16(cv::v_pack(pairs(u0 + l0), pairs(u1 + l1)));
  };
  const auto chroma = [&](const cv::v_int16x8& b, const cv::v_int16x8& g, const cv::v_int16x8& r,
                          const cv::v_int16x8& blueGreen, const cv::v_int16x8& redRound,
                          std::uint8_t* into) {
    cv::v_int16x8 bg0, bg1, r10, r11;
    cv::v_zip(b, g, bg0, bg1);
    cv::v_zip(r, ones, r10, r11);
    const auto shifted = [&](const cv::v_int16x8& bg, const cv::v_int16x8& r1) {
      return cv::v_shr<10>(cv::v_dotprod(bg, blueGreen) + cv::v_dotprod(r1, redRound)) +
             chromaCentre;
    };
    const cv::v_int16x8 words = cv::v_pack(shifted(bg0, r10), shifted(bg1, r11));
    cv::v_pack_u_store(into, words);
  };

  int x = 0;
  for (; x + kVectorPixels <= width; x += kVectorPixels) {
    cv::v_uint8x16 bt, gt, rt, bb, gb, rb;
    cv::v_load_deinterleave(top + std::ptrdiff_t{3} * x, bt, gt, rt);
    cv::v_load_deinterleave(bottom + std::ptrdiff_t{3} * x, bb, gb, rb);
    luma(bt, gt, rt, out.lumaTop + x);
    luma(bb, gb, rb, out.lumaBottom + x);
    const cv::v_int16x8 b = blockSums(bt, bb);
    const cv::v_int16x8 g = blockSums(gt, gb);
    const cv::v_int16x8 r = blockSums(rt, rb);
    chroma(b, g, r, cbBlueGreen, cbRedRound, out.cb + x / 2);
    chroma(b, g, r, crBlueGreen, crRedRound, out.cr + x / 2);
  }
  return x;
}
#endif

}  // namespace

void bgrRowsToI420(const cv::Mat& bgr, int first, int last, cv::Mat& i420, KernelPath path) {
  if (!kernelPathBuilt(path)) {
    throw std::invalid_argument(
        fmt::format("I420: this build has no {} kernels", kernelPathName(path)));
  }
  const int width = bgr.cols;
  const int height = bgr.rows;
  std::uint8_t* cbPlane = i420.ptr<std::uint8_t>(height);
  std::uint8_t* crPlane = cbPlane + static_cast<std::size_t>(width / 2) * (height / 2);
  for (int y = first; y < last; y += 2) {
    const std::size_t chromaRow = static_cast<std::size_t>(y / 2) * (width / 2);
    const Planes out{i420.ptr<std::uint8_t>(y), i420.ptr<std::uint8_t>(y + 1), cbPlane + chromaRow,
                     crPlane + chromaRow};
    const std::uint8_t* top = bgr.ptr<std::uint8_t>(y);
    const std::uint8_t* bottom = bgr.ptr<std::uint8_t>(y + 1);
    int done = 0;
#if CV_SIMD128
    if (path != KernelPath::kPortable) done = convertVectors(top, bottom, width, out);
#endif
    convertBlocks(top, bottom, done, width, out);
  }
}

void bgrToI420(const cv::Mat& bgr, cv::Mat& i420, WorkPool& pool) {
  if (bgr.type() != CV_8UC3 || bgr.cols % 2 != 0 || bgr.rows % 2 != 0) {
    throw std::invalid_argument(
        fmt::format("I420: expected an 8-bit BGR picture of even sides, got {}x{} of type {}",
                    bgr.cols, bgr.rows, bgr.type()));
  }
  i420.create(i420HeldSize(bgr.size()), CV_8UC1);
  pool.parallelFor(
      bgr.rows / 2, [&](int first, int last) { bgrRowsToI420(bgr, 2 * first, 2 * last, i420); },
      pool.threads() * 4);
}

}  // namespace surroundd::processing
