#pragma once
// A repeating (wrap-around) texture with a mip pyramid and trilinear sampling.
//
// Why a pyramid: the cameras see the ground from a few centimetres to tens of metres away, so one
// pixel covers anything from a fraction of a texel to thousands of texels. Point-sampling the fine
// asphalt grain would alias into crawling noise that no real lens produces; sampling the level
// whose texel matches the pixel's footprint (the caller computes lod = log2(footprint / texel))
// keeps every camera, and the ground-truth panorama, seeing the same band-limited surface.
//
// Texture coordinates are in level-0 texels, texel i covering [i, i + 1). Width and height must be
// powers of two so that wrapping is a mask. Colours are BGR, 0..255, as floats.
//
// Memory layout: texels are stored in 8x8 blocks (256 bytes), and the whole pyramid sits in one
// allocation advised to use huge pages. A camera row crosses the ground texture in any direction;
// row-major storage made nearly every fetch a cache and TLB miss.

#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::synth {

class MipTexture {
 public:
  MipTexture() = default;
  // `level0` is CV_8UC3 (BGR) with power-of-two sides; the pyramid is built here with cv::pyrDown.
  explicit MipTexture(const cv::Mat& level0);

  int levels() const { return static_cast<int>(levels_.size()); }
  cv::Size size() const { return sizes_.empty() ? cv::Size() : sizes_[0]; }

  // Trilinear: bilinear in the two levels around `lod`, blended.
  cv::Vec3f sample(float u, float v, float lod) const { return toBgr(sampleFixed(u, v, lod)); }

  // The same in fixed point: 16-bit lanes B | R << 16 | G << 32, each 8.8 (value * 256).
  //
  // Why fixed point: texture filtering is most of the render time. Spreading a BGRA texel into
  // four 16-bit lanes of a 64-bit word lets one multiply weight all channels at once (SWAR); with
  // 8-bit weights summing to 256 no lane can overflow into the next. Portable, no intrinsics.
  std::uint64_t sampleFixed(float u, float v, float lod) const {
    const float maxLod = static_cast<float>(levels_.size() - 1);
    lod = lod < 0 ? 0 : (lod > maxLod ? maxLod : lod);
    const int l0 = static_cast<int>(lod);
    const auto f = static_cast<std::uint64_t>((lod - static_cast<float>(l0)) * 256.0f);
    // Level-0 position in 1/256 texel, once; level l is the same shifted right by l.
    const int x = floorToInt(u * 256.0f);
    const int y = floorToInt(v * 256.0f);
    const std::uint64_t a = bilinearFixed(l0, x, y);
    if (f < 4 || l0 + 1 >= static_cast<int>(levels_.size())) return a;
    const std::uint64_t b = bilinearFixed(l0 + 1, x, y);
    // Back to 8-bit lanes (rounded) so that the blend, again with weights summing to 256, fits.
    constexpr std::uint64_t kHalf = 0x0000'0080'0080'0080ULL;
    constexpr std::uint64_t kLanes = 0x0000'00ff'00ff'00ffULL;
    const std::uint64_t a8 = ((a + kHalf) >> 8) & kLanes;
    const std::uint64_t b8 = ((b + kHalf) >> 8) & kLanes;
    return a8 * (256 - f) + b8 * f;
  }

  cv::Vec3f bilinear(int level, float u, float v) const {
    return toBgr(bilinearFixed(level, floorToInt(u * 256.0f), floorToInt(v * 256.0f)));
  }

  // (x256, y256): level-0 position in 1/256 texel.
  std::uint64_t bilinearFixed(int level, int x256, int y256) const {
    const Level& l = levels_[static_cast<std::size_t>(level)];
    // Texel centres sit at i + 0.5 (128 in 1/256 units); shifts floor negatives too.
    const int x = (x256 >> level) - 128;
    const int y = (y256 >> level) - 128;
    const auto wx = static_cast<std::uint32_t>(x & 255);
    const auto wy = static_cast<std::uint32_t>(y & 255);
    const int x0 = (x >> 8) & l.widthMask;
    const int y0 = (y >> 8) & l.heightMask;
    const int x1 = (x0 + 1) & l.widthMask;
    const int y1 = (y0 + 1) & l.heightMask;
    const std::ptrdiff_t row0 = blockRow(l, y0), row1 = blockRow(l, y1);
    const std::ptrdiff_t col0 = blockColumn(x0), col1 = blockColumn(x1);
    const std::uint64_t w10 = (wx * (256 - wy)) >> 8;
    const std::uint64_t w01 = ((256 - wx) * wy) >> 8;
    const std::uint64_t w11 = (wx * wy) >> 8;
    const std::uint64_t w00 = 256 - w10 - w01 - w11;
    return spread(l.texels[row0 + col0]) * w00 + spread(l.texels[row0 + col1]) * w10 +
           spread(l.texels[row1 + col0]) * w01 + spread(l.texels[row1 + col1]) * w11;
  }

  static cv::Vec3f toBgr(std::uint64_t fixed) {
    constexpr float kScale = 1.0f / 256.0f;
    return {static_cast<float>(fixed & 0xffffU) * kScale,
            static_cast<float>((fixed >> 32) & 0xffffU) * kScale,
            static_cast<float>((fixed >> 16) & 0xffffU) * kScale};
  }

 private:
  struct Level {
    const std::uint32_t* texels = nullptr;  // BGRA, 4 bytes per texel: one load per texel
    std::ptrdiff_t blocksPerRow = 0;
    int widthMask = 0;
    int heightMask = 0;
  };

  // BGRA bytes to 16-bit lanes: B in bits 0..15, R in 16..31, G in 32..47 (A in 48..63).
  static std::uint64_t spread(std::uint32_t texel) {
    const std::uint64_t t = texel;
    return (t & 0x00ff00ffULL) | ((t & 0x0000ff00ULL) << 24);
  }
  // Offset of texel (x, y) in 8x8 blocks: row part + column part.
  static std::ptrdiff_t blockRow(const Level& l, int y) {
    return ((y >> 3) * l.blocksPerRow << 6) + ((y & 7) << 3);
  }
  static std::ptrdiff_t blockColumn(int x) { return ((x >> 3) << 6) + (x & 7); }
  static int floorToInt(float x) {
    const int i = static_cast<int>(x);
    return i - (x < static_cast<float>(i) ? 1 : 0);
  }

  struct Free {
    void operator()(std::uint32_t* p) const;
  };
  std::unique_ptr<std::uint32_t[], Free> storage_;  // all levels, blocked
  std::vector<cv::Size> sizes_;
  std::vector<Level> levels_;
};

}  // namespace surroundd::synth
