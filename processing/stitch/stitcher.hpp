#pragma once
// Applies a PanoramaLut to one frame per camera: bilinear samples, blended across the seams.
//
// Set up once per LUT; stitch() is the per-frame call. It runs on the work pool, allocates
// nothing, and writes PanoramaLut::kUnseenColour where no camera sees (lut.validMask() says
// where). Integer arithmetic throughout, so the result does not depend on the thread count.

#include <array>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/stitch/kernel_path.hpp"
#include "processing/stitch/panorama_lut.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::processing {

class Stitcher {
 public:
  // Borrows both: the LUT and the pool must outlive the stitcher.
  Stitcher(const PanoramaLut& lut, WorkPool& pool);

  // frames[i]: camera i's image, 8-bit 3-channel (any channel order; the panorama keeps it),
  // continuous, of the LUT's size for that camera. `panorama` is (re)allocated only if it is not
  // already 8-bit 3-channel of the LUT's size. Throws std::invalid_argument for frames that do not
  // match; that is a wiring error, caught by the first frame. `path`: the kernels, this machine's
  // unless a test compares them (each path stitches the same bytes); one this build lacks throws
  // std::invalid_argument.
  void stitch(std::span<const cv::Mat> frames, cv::Mat& panorama, KernelPath path = kNativeKernels);

  const PanoramaLut& lut() const { return lut_; }

 private:
  template <KernelPath kPath>
  void stitchRows(int first, int last, cv::Mat& panorama) const;

  const PanoramaLut& lut_;
  WorkPool& pool_;
  // Where each camera index's pixels start this frame; index kUnseen points at a 2x2 image of the
  // unseen colour, so unseen pixels need no branch.
  // Indexed by a tap's camera byte as it is, kUnseen included: no bounds check per pixel.
  static constexpr std::size_t kCameraByteValues = std::size_t{1} << (8 * sizeof(LutTap::camera));
  std::array<const std::uint8_t*, kCameraByteValues> sources_{};
  std::array<std::size_t, kCameraByteValues> rowBytes_{};
  cv::Mat unseen_;
  std::vector<std::pair<int, int>> seenSpans_;  // per row: [begin, end) columns to sample
};

}  // namespace surroundd::processing
