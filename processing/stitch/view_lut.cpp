#include "processing/stitch/view_lut.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <vector>

#include <fmt/core.h>

#include "common/work_pool.hpp"

namespace surroundd::processing {
namespace {

// One camera's part in a view pixel, summed over the panorama pixels around it.
struct CameraPart {
  std::uint8_t camera = PanoramaLut::kUnseen;
  double share = 0;           // of the view pixel's colour
  double positionWeight = 0;  // bilinear weights of the panorama pixels it was seen from
  cv::Point2d weightedPosition;
};

// Every camera that can reach a view pixel: two per panorama pixel, four panorama pixels.
using CameraParts = std::array<CameraPart, 8>;

cv::Point2d tapPosition(const LutTap& tap, cv::Size size) {
  const auto width = static_cast<std::uint32_t>(size.width);
  const std::uint32_t row = tap.offset / width;
  const std::uint32_t column = tap.offset % width;
  constexpr double kFraction = 1.0 / LutTap::kFractionOne;
  return {column + tap.fx * kFraction, row + tap.fy * kFraction};
}

class ViewLutComposer {
 public:
  explicit ViewLutComposer(const PanoramaLut& panorama)
      : panorama_(panorama), blendOf_(panorama.taps.size(), -1) {
    for (std::size_t i = 0; i < panorama.blendTaps.size(); ++i) {
      blendOf_[panorama.blendTaps[i].pixel] = static_cast<std::int32_t>(i);
    }
  }

  // The taps of the view pixel that samples the panorama at `position`; `blend` gets a camera
  // (weight > 0) when a second one takes part.
  LutTap compose(cv::Point2f position, LutTap& blend) const {
    const cv::Size size = panorama_.size;
    const double x = position.x;
    const double y = position.y;
    const double left = std::floor(x);
    const double top = std::floor(y);
    const double ax = x - left;
    const double ay = y - top;
    CameraParts parts{};
    for (int corner = 0; corner < 4; ++corner) {
      const double weight = ((corner & 1) != 0 ? ax : 1 - ax) * ((corner & 2) != 0 ? ay : 1 - ay);
      if (weight <= 0) continue;
      int column = static_cast<int>(left) + (corner & 1);
      column = ((column % size.width) + size.width) % size.width;
      const int row = std::clamp(static_cast<int>(top) + (corner >> 1), 0, size.height - 1);
      const auto pixel = static_cast<std::size_t>(row) * static_cast<std::size_t>(size.width) +
                         static_cast<std::size_t>(column);
      const LutTap& tap = panorama_.taps[pixel];
      const std::int32_t blendIndex = blendOf_[pixel];
      double blendShare = 0;
      if (blendIndex >= 0) {
        const LutTap& other = panorama_.blendTaps[static_cast<std::size_t>(blendIndex)].tap;
        blendShare = other.weight / 256.0;
        add(parts, other, weight * blendShare, weight);
      }
      add(parts, tap, weight * (1 - blendShare), weight);
    }
    blend = {};
    std::partial_sort(parts.begin(), parts.begin() + 2, parts.end(),
                      [](const CameraPart& a, const CameraPart& b) { return a.share > b.share; });
    const LutTap primary = encodeOf(parts[0]);
    if (parts[1].share > 0) {
      const auto weight =
          static_cast<int>(std::lround(256 * parts[1].share / (parts[0].share + parts[1].share)));
      if (weight > 0) {
        blend = encodeOf(parts[1]);
        blend.weight = static_cast<std::uint8_t>(weight);
      }
    }
    return primary;
  }

 private:
  // Where no camera sees, the renderer blends in the panorama's unseen colour: the stitcher's
  // kUnseen "camera", at no position.
  void add(CameraParts& parts, const LutTap& tap, double share, double weight) const {
    for (CameraPart& part : parts) {
      if (part.share > 0 && part.camera != tap.camera) continue;
      part.camera = tap.camera;
      part.share += share;
      if (tap.camera == PanoramaLut::kUnseen) return;
      part.positionWeight += weight;
      part.weightedPosition += weight * tapPosition(tap, panorama_.cameraSizes[tap.camera]);
      return;
    }
  }

  LutTap encodeOf(const CameraPart& part) const {
    if (part.camera == PanoramaLut::kUnseen) return {0, 0, 0, PanoramaLut::kUnseen, 0};
    return encodeTap(part.weightedPosition / part.positionWeight,
                     panorama_.cameraSizes[part.camera], part.camera);
  }

  const PanoramaLut& panorama_;
  std::vector<std::int32_t> blendOf_;  // per panorama pixel: its blend tap, -1 for none
};

}  // namespace

PanoramaLut composeViewLut(const PanoramaLut& panorama, const cv::Mat& panoramaPositions,
                           WorkPool& pool) {
  if (panoramaPositions.type() != CV_32FC2 || panoramaPositions.empty()) {
    throw std::invalid_argument(fmt::format(
        "view LUT: panorama positions must be a non-empty CV_32FC2 picture, got type {}",
        panoramaPositions.type()));
  }
  const ViewLutComposer composer(panorama);
  const cv::Size size = panoramaPositions.size();
  PanoramaLut view;
  view.size = size;
  view.cameraSizes = panorama.cameraSizes;
  view.taps.resize(static_cast<std::size_t>(size.area()));
  std::vector<std::vector<BlendTap>> blendRows(static_cast<std::size_t>(size.height));
  pool.parallelFor(
      size.height,
      [&](int first, int last) {
        for (int v = first; v < last; ++v) {
          const auto* positions = panoramaPositions.ptr<cv::Point2f>(v);
          auto& blendRow = blendRows[static_cast<std::size_t>(v)];
          for (int u = 0; u < size.width; ++u) {
            const auto pixel = static_cast<std::uint32_t>(v * size.width + u);
            LutTap& tap = view.taps[pixel];
            if (!std::isfinite(positions[u].x) || !std::isfinite(positions[u].y)) {
              tap.camera = PanoramaLut::kUnseen;
              continue;
            }
            LutTap blend;
            tap = composer.compose(positions[u], blend);
            if (blend.weight > 0) blendRow.push_back({pixel, blend});
          }
        }
      },
      pool.threads() * 4);
  view.blendRowBegin.reserve(static_cast<std::size_t>(size.height) + 1);
  for (const auto& blendRow : blendRows) {
    view.blendRowBegin.push_back(static_cast<std::uint32_t>(view.blendTaps.size()));
    view.blendTaps.insert(view.blendTaps.end(), blendRow.begin(), blendRow.end());
  }
  view.blendRowBegin.push_back(static_cast<std::uint32_t>(view.blendTaps.size()));
  return view;
}

}  // namespace surroundd::processing
