#pragma once
// Robust seam data for Poisson colour correction on real rigs (DESIGN.md §2.8).
//
// A plain mean of a seam block's pixels is poisoned by anything the two cameras do not see alike:
// parallax on objects standing near the seam, a bumper or a reflection on the car's own paint,
// clipped highlights, sensor noise in the dark. So each block is measured as the trimmed mean (the
// middle half) of each camera's usable samples (not too dark to measure a gain, not clipped), a
// block with too few of them does not count, and the values are then filtered along the seam with a
// running median, so that an object a few blocks long is outvoted by the ground on either side of
// it.

#include <cstdint>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/colour/correction_domain.hpp"
#include "processing/stitch/bilinear_sample.hpp"

namespace surroundd::processing {

// One seam block's measurement: the trimmed mean level of each camera over the samples both see.
struct SeamBlockLevels {
  cv::Vec3f target;
  cv::Vec3f source;
  bool valid = false;
};

class SeamBlockMeter {
 public:
  // Samples at most `maxSamples` per block (the block's pixels).
  explicit SeamBlockMeter(std::size_t maxSamples);

  // A block counts when at least half its samples are usable.
  SeamBlockLevels measure(const CorrectionDomain& domain, const DirichletBlock& block,
                          const SampledImage& target, const SampledImage& source);

 private:
  std::vector<float> scratch_;  // 6 channels x maxSamples
  std::size_t maxSamples_;
};

// Running median along a seam of the valid blocks' values (3 per block), into `filtered`; a block
// with no valid block within `halfWindow` gets 0 and is marked invalid in `filteredValid`. No
// allocation: `window` must hold 2 * halfWindow + 1 floats.
void medianAlongSeam(std::span<const std::uint32_t> blocks, std::span<const float> values,
                     std::span<const std::uint8_t> valid, int halfWindow, std::span<float> window,
                     std::span<float> filtered, std::span<std::uint8_t> filteredValid);

}  // namespace surroundd::processing
