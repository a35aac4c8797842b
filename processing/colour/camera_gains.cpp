#include "processing/colour/camera_gains.hpp"

#include "common/work_pool.hpp"

namespace surroundd::processing {

void applyCameraGains(cv::Mat& picture, const PanoramaLut& lut, std::span<const cv::Vec3f> gains,
                      WorkPool& pool) {
  const int width = lut.size.width;
  pool.parallelFor(
      lut.size.height,
      [&](int first, int last) {
        for (int v = first; v < last; ++v) {
          auto* out = picture.ptr<cv::Vec3b>(v);
          const LutTap* taps = lut.taps.data() + static_cast<std::size_t>(v) * width;
          const std::uint32_t rowStart =
              static_cast<std::uint32_t>(v) * static_cast<std::uint32_t>(width);
          auto blend = lut.blendTaps.begin() + lut.blendRowBegin[v];
          const auto blendEnd = lut.blendTaps.begin() + lut.blendRowBegin[v + 1];
          for (int u = 0; u < width; ++u) {
            const LutTap* other = nullptr;
            if (blend != blendEnd && blend->pixel == rowStart + static_cast<std::uint32_t>(u)) {
              other = &blend->tap;
              ++blend;
            }
            if (taps[u].camera == PanoramaLut::kUnseen) continue;
            cv::Vec3f gain = gains[taps[u].camera];
            // In a seam band the pixel mixes two cameras, a and b, which differ before the gains
            // and agree after them (g_a a = g_b b = x): the pixel p = (1 - w) a + w b is
            // x ((1 - w) / g_a + w / g_b), so it takes the gains' harmonic mix. Their plain mix
            // would leave the band off by the cameras' difference. (A view's pixel at the edge
            // of what the cameras see mixes in the unseen colour, which no gain changes.)
            if (other != nullptr && other->camera != PanoramaLut::kUnseen) {
              const float weight = other->weight / 256.0f;
              const cv::Vec3f& otherGain = gains[other->camera];
              for (int c = 0; c < 3; ++c) {
                gain[c] = 1 / ((1 - weight) / gain[c] + weight / otherGain[c]);
              }
            }
            for (int c = 0; c < 3; ++c)
              out[u][c] = cv::saturate_cast<std::uint8_t>(out[u][c] * gain[c]);
          }
        }
      },
      pool.threads() * 4);
}

}  // namespace surroundd::processing
