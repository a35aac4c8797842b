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

#include "common/pixel_format.hpp"
#include "processing/stitch/bilinear_sample.hpp"
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

  // frames[i]: camera i's frame held in `format` (common/pixel_format.hpp), continuous, of the
  // LUT's size for that camera; BGR frames may be in any channel order (the panorama keeps it),
  // YUV ones are converted to BGR sample by sample. `panorama` (8-bit 3-channel) is (re)allocated
  // only if it is not already of the LUT's size. Throws std::invalid_argument for frames that do
  // not match; that is a wiring error, caught by the first frame. `path`: the kernels, this
  // machine's unless a test compares them (each path stitches the same bytes); one this build
  // lacks throws std::invalid_argument.
  void stitch(std::span<const cv::Mat> frames, PixelFormat format, cv::Mat& panorama,
              KernelPath path = kNativeKernels);
  void stitch(std::span<const cv::Mat> frames, cv::Mat& panorama,
              KernelPath path = kNativeKernels) {
    stitch(frames, PixelFormat::kBgr, panorama, path);
  }

  const PanoramaLut& lut() const { return lut_; }

 private:
  using RowKernel = void (Stitcher::*)(int, int, cv::Mat&) const;
  template <KernelPath kPath>
  static RowKernel rowsOf(PixelFormat format);
  static RowKernel rowsFor(KernelPath path, PixelFormat format);
  template <KernelPath kPath, PixelFormat kFormat>
  void stitchRows(int first, int last, cv::Mat& panorama) const;

  const PanoramaLut& lut_;
  WorkPool& pool_;
  // Each camera index's frame this stitch; index kUnseen is a 2x2 picture of the unseen colour
  // (black, in every format) in the frames' format, so unseen pixels need no branch.
  // Indexed by a tap's camera byte as it is, kUnseen included: no bounds check per pixel.
  static constexpr std::size_t kCameraByteValues = std::size_t{1} << (8 * sizeof(LutTap::camera));
  std::array<SampledImage, kCameraByteValues> images_{};
  std::array<cv::Mat, kPixelFormats> unseen_;   // per PixelFormat
  std::vector<std::pair<int, int>> seenSpans_;  // per row: [begin, end) columns to sample
};

}  // namespace surroundd::processing
