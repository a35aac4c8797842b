#include "processing/gain_compensation.hpp"

#include <algorithm>
#include <cmath>

#include "common/work_pool.hpp"
#include "processing/bilinear_sample.hpp"

namespace surroundd::processing {
namespace {

// Brown & Lowe's weights: the spread of intensity differences in an overlap against the spread
// of gains; a gain costs as much as this many levels of mismatch per unit away from 1.
constexpr double kSigmaLevels = 10.0;
constexpr double kSigmaGain = 0.1;
// Every n-th blend pixel is enough for a mean over an overlap.
constexpr std::size_t kOverlapStride = 3;

cv::Vec3d channels(std::uint32_t packed) {
  return {static_cast<double>(packed & 0xffU), static_cast<double>((packed >> 8) & 0xffU),
          static_cast<double>((packed >> 16) & 0xffU)};
}

}  // namespace

GainCompensation::GainCompensation(const PanoramaLut& lut, WorkPool& pool)
    : lut_(lut), pool_(pool), gains_(lut.cameraSizes.size(), cv::Vec3f(1, 1, 1)) {
  for (std::size_t i = 0; i < lut.blendTaps.size(); i += kOverlapStride) {
    overlap_.push_back(lut.blendTaps[i]);
    overlapOwner_.push_back(lut.taps[lut.blendTaps[i].pixel]);
  }
  const std::size_t n = gains_.size();
  sums_.assign(n * n, cv::Vec3d());
  counts_.assign(n * n, 0);
}

void GainCompensation::update(std::span<const cv::Mat> frames) {
  const std::size_t n = gains_.size();
  std::fill(sums_.begin(), sums_.end(), cv::Vec3d());
  std::fill(counts_.begin(), counts_.end(), 0.0);
  for (std::size_t k = 0; k < overlap_.size(); ++k) {
    const LutTap& a = overlapOwner_[k];
    const LutTap& b = overlap_[k].tap;
    const cv::Mat& imageA = frames[a.camera];
    const cv::Mat& imageB = frames[b.camera];
    if (imageA.empty() || imageB.empty()) continue;
    sums_[a.camera * n + b.camera] += channels(bilinear(imageA.data, imageA.step, a));
    sums_[b.camera * n + a.camera] += channels(bilinear(imageB.data, imageB.step, b));
    counts_[a.camera * n + b.camera] += 1;
    counts_[b.camera * n + a.camera] += 1;
  }
  // Minimize sum over pairs N_ij (g_i m_ij - g_j m_ji)^2 / s_N^2 + sum (1 - g_i)^2 / s_g^2, per
  // channel: a small symmetric system (n x n).
  for (int c = 0; c < 3; ++c) {
    cv::Mat a(static_cast<int>(n), static_cast<int>(n), CV_64F, cv::Scalar(0));
    cv::Mat rhs(static_cast<int>(n), 1, CV_64F, cv::Scalar(0));
    for (std::size_t i = 0; i < n; ++i) {
      a.at<double>(static_cast<int>(i), static_cast<int>(i)) += 1 / (kSigmaGain * kSigmaGain);
      rhs.at<double>(static_cast<int>(i)) += 1 / (kSigmaGain * kSigmaGain);
      for (std::size_t j = 0; j < n; ++j) {
        const double count = counts_[i * n + j];
        if (i == j || count == 0) continue;
        const double mij = sums_[i * n + j][c] / count;
        const double mji = sums_[j * n + i][c] / count;
        const double w = count / (kSigmaLevels * kSigmaLevels);
        a.at<double>(static_cast<int>(i), static_cast<int>(i)) += w * mij * mij;
        a.at<double>(static_cast<int>(i), static_cast<int>(j)) -= w * mij * mji;
      }
    }
    cv::Mat g;
    if (!cv::solve(a, rhs, g, cv::DECOMP_CHOLESKY)) continue;
    for (std::size_t i = 0; i < n; ++i) {
      if (!frames[i].empty()) gains_[i][c] = static_cast<float>(g.at<double>(static_cast<int>(i)));
    }
  }
}

void GainCompensation::apply(cv::Mat& panorama) {
  const int width = lut_.size.width;
  pool_.parallelFor(
      lut_.size.height,
      [&](int first, int last) {
        for (int v = first; v < last; ++v) {
          auto* out = panorama.ptr<cv::Vec3b>(v);
          const LutTap* taps = lut_.taps.data() + static_cast<std::size_t>(v) * width;
          const std::uint32_t rowStart =
              static_cast<std::uint32_t>(v) * static_cast<std::uint32_t>(width);
          auto blend = lut_.blendTaps.begin() + lut_.blendRowBegin[v];
          const auto blendEnd = lut_.blendTaps.begin() + lut_.blendRowBegin[v + 1];
          for (int u = 0; u < width; ++u) {
            if (taps[u].camera == PanoramaLut::kUnseen) continue;
            cv::Vec3f gain = gains_[taps[u].camera];
            // In a seam band the pixel mixes two cameras: so do their gains.
            if (blend != blendEnd && blend->pixel == rowStart + static_cast<std::uint32_t>(u)) {
              const float weight = blend->tap.weight / 256.0f;
              gain = gain * (1 - weight) + gains_[blend->tap.camera] * weight;
              ++blend;
            }
            for (int c = 0; c < 3; ++c)
              out[u][c] = cv::saturate_cast<std::uint8_t>(out[u][c] * gain[c]);
          }
        }
      },
      pool_.threads() * 4);
}

}  // namespace surroundd::processing
