#include "processing/colour/gain_compensation.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "processing/colour/camera_gains.hpp"
#include "processing/stitch/bilinear_sample.hpp"

namespace surroundd::processing {
namespace {

// Brown & Lowe's weights: the spread of intensity differences in an overlap against the spread
// of gains; a gain costs as much as this many levels of mismatch per unit away from 1.
constexpr double kSigmaLevels = 10.0;
constexpr double kSigmaGain = 0.1;
// Every n-th blend pixel is enough for a mean over an overlap.
constexpr std::size_t kOverlapStride = 3;

// Levels this close to black or white say nothing about a gain (noise, clipping).
constexpr unsigned kDarkestUsable = 4;
constexpr unsigned kBrightestUsable = 250;

bool usable(std::uint32_t pixel) {
  for (int c = 0; c < 3; ++c) {
    const unsigned level = (pixel >> (8 * c)) & 0xffU;
    if (level < kDarkestUsable || level > kBrightestUsable) return false;
  }
  return true;
}

double median(const std::array<int, 256>& histogram, double count) {
  double seen = 0;
  for (int level = 0; level < 256; ++level) {
    seen += histogram[static_cast<std::size_t>(level)];
    if (seen >= count / 2) return level;
  }
  return 255;
}

}  // namespace

GainCompensation::GainCompensation(const PanoramaLut& lut, WorkPool& pool, double minGain,
                                   double maxGain, std::vector<std::string> cameraNames)
    : lut_(lut),
      pool_(pool),
      names_(std::move(cameraNames)),
      minGain_(minGain),
      maxGain_(maxGain),
      gains_(lut.cameraSizes.size(), cv::Vec3f(1, 1, 1)),
      sorted_(lut.cameraSizes.size(), 0.0),
      saidClamped_(lut.cameraSizes.size(), 0) {
  for (std::size_t i = 0; i < lut.blendTaps.size(); i += kOverlapStride) {
    overlap_.push_back(lut.blendTaps[i]);
    overlapOwner_.push_back(lut.taps[lut.blendTaps[i].pixel]);
  }
  const std::size_t n = gains_.size();
  for (std::size_t c = names_.size(); c < n; ++c) names_.push_back(std::to_string(c));
  histograms_.assign(n * n * 3, {});
  counts_.assign(n * n, 0);
}

void GainCompensation::update(std::span<const cv::Mat> frames, PixelFormat format) {
  const std::size_t n = gains_.size();
  notes_.clear();
  for (auto& histogram : histograms_) histogram.fill(0);
  std::fill(counts_.begin(), counts_.end(), 0.0);
  const auto add = [&](std::size_t i, std::size_t j, std::uint32_t pixel) {
    for (std::size_t c = 0; c < 3; ++c)
      ++histograms_[(i * n + j) * 3 + c][(pixel >> (8 * c)) & 0xffU];
  };
  for (std::size_t k = 0; k < overlap_.size(); ++k) {
    const LutTap& a = overlapOwner_[k];
    const LutTap& b = overlap_[k].tap;
    const cv::Mat& imageA = frames[a.camera];
    const cv::Mat& imageB = frames[b.camera];
    if (imageA.empty() || imageB.empty()) continue;
    const std::uint32_t pixelA = bilinear(SampledImage::of(imageA, format), a);
    const std::uint32_t pixelB = bilinear(SampledImage::of(imageB, format), b);
    if (!usable(pixelA) || !usable(pixelB)) continue;
    add(a.camera, b.camera, pixelA);
    add(b.camera, a.camera, pixelB);
    counts_[a.camera * n + b.camera] += 1;
    counts_[b.camera * n + a.camera] += 1;
  }
  // Brown & Lowe: minimize sum over pairs N_ij (g_i m_ij - g_j m_ji)^2 / s_N^2 + sum (1 - g_i)^2 /
  // s_g^2, per channel: a small symmetric system (n x n). Thousands of overlap pixels outvote the
  // prior, which only fixes the scale, and least squares sinks towards dimmer gains (to 0.02 on a
  // real rig): the ratios between gains are what the overlaps tell, the scale is set afterwards.
  for (int c = 0; c < 3; ++c) {
    cv::Mat a(static_cast<int>(n), static_cast<int>(n), CV_64F, cv::Scalar(0));
    cv::Mat rhs(static_cast<int>(n), 1, CV_64F, cv::Scalar(0));
    double overlapCount = 0;
    for (std::size_t i = 0; i < n; ++i) {
      a.at<double>(static_cast<int>(i), static_cast<int>(i)) += 1 / (kSigmaGain * kSigmaGain);
      rhs.at<double>(static_cast<int>(i)) += 1 / (kSigmaGain * kSigmaGain);
      for (std::size_t j = 0; j < n; ++j) {
        const double count = counts_[i * n + j];
        if (i == j || count == 0) continue;
        const double mij =
            median(histograms_[(i * n + j) * 3 + static_cast<std::size_t>(c)], count);
        const double mji =
            median(histograms_[(j * n + i) * 3 + static_cast<std::size_t>(c)], count);
        const double w = count / (kSigmaLevels * kSigmaLevels);
        a.at<double>(static_cast<int>(i), static_cast<int>(i)) += w * mij * mij;
        a.at<double>(static_cast<int>(i), static_cast<int>(j)) -= w * mij * mji;
        overlapCount += count;
      }
    }
    cv::Mat g;
    if (overlapCount == 0 || !cv::solve(a, rhs, g, cv::DECOMP_CHOLESKY)) continue;
    // Least squares fixes only the gains' ratios well; their scale is set so that the median
    // camera keeps its level: the rig's brightness stays where most of its cameras have it, and a
    // camera far off (a wrong exposure, its body in the overlaps) is the one that moves.
    double* gain = g.ptr<double>();
    std::size_t present = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (!frames[i].empty()) sorted_[present++] = gain[i];
    }
    if (present == 0) continue;
    std::nth_element(sorted_.begin(), sorted_.begin() + static_cast<std::ptrdiff_t>(present / 2),
                     sorted_.begin() + static_cast<std::ptrdiff_t>(present));
    double middle = sorted_[present / 2];
    if (present % 2 == 0) {
      middle =
          (middle + *std::max_element(sorted_.begin(),
                                      sorted_.begin() + static_cast<std::ptrdiff_t>(present / 2))) /
          2;
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (frames[i].empty() || middle <= 0) continue;
      const double scaled = gain[i] / middle;
      const double bounded = std::clamp(scaled, minGain_, maxGain_);
      if (bounded != scaled && saidClamped_[i] == 0) {
        saidClamped_[i] = 1;
        notes_.push_back(fmt::format(
            "camera '{}': gain {:.2f} (channel {}) is outside {:g}..{:g}: clamped; its overlaps "
            "disagree with its neighbours' more than exposure and white balance explain",
            names_[i], scaled, "BGR"[c], minGain_, maxGain_));
      }
      gains_[i][c] = static_cast<float>(bounded);
    }
  }
}

void GainCompensation::apply(cv::Mat& picture, const PanoramaLut& lut) {
  applyCameraGains(picture, lut, gains_, pool_);
}

}  // namespace surroundd::processing
