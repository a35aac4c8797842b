#include "processing/stitch/panorama_ownership.hpp"

namespace surroundd::processing {

PanoramaOwnership::PanoramaOwnership(const PanoramaLut& lut) : runs_(lut.cameraSizes.size()) {
  for (int v = 0; v < lut.size.height; ++v) {
    const LutTap* row = lut.taps.data() + static_cast<std::size_t>(v) * lut.size.width;
    int u = 0;
    while (u < lut.size.width) {
      const std::uint8_t camera = row[u].camera;
      const int begin = u;
      while (u < lut.size.width && row[u].camera == camera) ++u;
      if (camera != PanoramaLut::kUnseen) {
        runs_[camera].push_back({static_cast<std::uint16_t>(v), static_cast<std::uint16_t>(begin),
                                 static_cast<std::uint16_t>(u)});
      }
    }
  }
}

void PanoramaOwnership::markFaulty(cv::Mat& panorama, std::size_t camera) const {
  constexpr int kStripe = 16;  // pixels per stripe period along the diagonal
  for (const Run& run : runs_.at(camera)) {
    auto* pixel = panorama.ptr<std::uint8_t>(run.row) + 3 * static_cast<std::size_t>(run.begin);
    for (int u = run.begin; u < run.end; ++u, pixel += 3) {
      const bool stripe = ((u + run.row) / (kStripe / 2)) % 2 == 0;
      for (int c = 0; c < 3; ++c) {
        // A quarter of the picture over mid grey; the stripes darker.
        pixel[c] = static_cast<std::uint8_t>(pixel[c] / 4 + (stripe ? 40 : 100));
      }
    }
  }
}

}  // namespace surroundd::processing
