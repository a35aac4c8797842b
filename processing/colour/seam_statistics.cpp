#include "processing/colour/seam_statistics.hpp"

#include <algorithm>

#include "processing/stitch/bilinear_sample.hpp"

namespace surroundd::processing {
namespace {

// Levels this close to black say nothing about a gain (noise and black level dominate them);
// this close to white, the sensor clipped.
constexpr int kDarkestUsable = 4;
constexpr int kBrightestUsable = 250;
constexpr double kMinimumUsableShare = 0.5;

float median(float* first, std::size_t count) {
  float* middle = first + count / 2;
  std::nth_element(first, middle, first + count);
  return *middle;
}

// The mean of the middle half: as robust as the median to a quarter of outliers on either side,
// and nearly as steady as the mean under sensor noise.
float trimmedMean(float* first, std::size_t count) {
  const std::size_t cut = count / 4;
  if (cut > 0) {
    std::nth_element(first, first + cut, first + count);
    std::nth_element(first + cut, first + (count - cut), first + count);
  }
  float sum = 0;
  for (std::size_t i = cut; i < count - cut; ++i) sum += first[i];
  return sum / static_cast<float>(count - 2 * cut);
}

bool usable(std::uint32_t pixel) {
  for (int c = 0; c < 3; ++c) {
    const auto level = static_cast<int>((pixel >> (8 * c)) & 0xffU);
    if (level < kDarkestUsable || level > kBrightestUsable) return false;
  }
  return true;
}

}  // namespace

SeamBlockMeter::SeamBlockMeter(std::size_t maxSamples)
    : scratch_(6 * std::max<std::size_t>(maxSamples, 1)), maxSamples_(maxSamples) {}

SeamBlockLevels SeamBlockMeter::measure(const CorrectionDomain& domain, const DirichletBlock& block,
                                        const SampledImage& target, const SampledImage& source) {
  SeamBlockLevels levels;
  std::size_t count = 0;
  for (auto s = block.firstSample; s < block.endSample && count < maxSamples_; ++s) {
    const SeamSample& sample = domain.samples[s];
    const std::uint32_t t = bilinear(target, sample.target);
    const std::uint32_t o = bilinear(source, sample.source);
    if (!usable(t) || !usable(o)) continue;
    for (int c = 0; c < 3; ++c) {
      scratch_[c * maxSamples_ + count] = static_cast<float>((t >> (8 * c)) & 0xffU);
      scratch_[(3 + c) * maxSamples_ + count] = static_cast<float>((o >> (8 * c)) & 0xffU);
    }
    ++count;
  }
  if (count == 0 ||
      static_cast<double>(count) < kMinimumUsableShare * (block.endSample - block.firstSample)) {
    return levels;
  }
  for (int c = 0; c < 3; ++c) {
    levels.target[c] = trimmedMean(scratch_.data() + c * maxSamples_, count);
    levels.source[c] = trimmedMean(scratch_.data() + (3 + c) * maxSamples_, count);
  }
  levels.valid = true;
  return levels;
}

void medianAlongSeam(std::span<const std::uint32_t> blocks, std::span<const float> values,
                     std::span<const std::uint8_t> valid, int halfWindow, std::span<float> window,
                     std::span<float> filtered, std::span<std::uint8_t> filteredValid) {
  const auto n = static_cast<int>(blocks.size());
  for (int i = 0; i < n; ++i) {
    const std::size_t block = blocks[static_cast<std::size_t>(i)];
    const int first = std::max(0, i - halfWindow);
    const int last = std::min(n - 1, i + halfWindow);
    for (int c = 0; c < 3; ++c) {
      std::size_t count = 0;
      for (int j = first; j <= last; ++j) {
        const std::size_t other = blocks[static_cast<std::size_t>(j)];
        if (valid[other] != 0) window[count++] = values[other * 3 + static_cast<std::size_t>(c)];
      }
      filtered[block * 3 + static_cast<std::size_t>(c)] =
          count == 0 ? 0.0f : median(window.data(), count);
      filteredValid[block] = count == 0 ? 0 : 1;
    }
  }
}

}  // namespace surroundd::processing
