#include "tools/synth/photometrics.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "tools/synth/hash.hpp"

namespace surroundd::synth {
namespace {

constexpr std::uint64_t kParameterStream = 21;
constexpr std::uint64_t kNoiseStream = 22;

// Standard normal quantiles at (i + 0.5) / 4096: a 12-bit random index then draws a Gaussian
// sample with one L1-resident load (three per pixel from one 64-bit hash), instead of a
// transcendental per channel. Tails reach 3.7 sigma, plenty for sensor noise.
constexpr int kGaussianBits = 12;
const std::array<float, 1 << kGaussianBits>& gaussianTable() {
  static const auto kTable = [] {
    std::array<float, 1 << kGaussianBits> t{};
    for (std::size_t i = 0; i < t.size(); ++i) {
      const double p = (static_cast<double>(i) + 0.5) / static_cast<double>(t.size());
      // Invert the normal CDF 0.5 * erfc(-z / sqrt 2) by bisection: set-up only.
      double lo = -10, hi = 10;
      for (int k = 0; k < 60; ++k) {
        const double mid = 0.5 * (lo + hi);
        (0.5 * std::erfc(-mid / std::numbers::sqrt2) < p ? lo : hi) = mid;
      }
      t[i] = static_cast<float>(0.5 * (lo + hi));
    }
    return t;
  }();
  return kTable;
}

}  // namespace

double CameraPhotometrics::exposureAt(double seconds) const {
  if (driftAmplitude == 0 || driftPeriodS <= 0) return 1.0;
  return 1.0 +
         driftAmplitude * std::sin(2 * std::numbers::pi * seconds / driftPeriodS + driftPhaseRad);
}

double CameraPhotometrics::vignetteAt(double offAxisRad, bool fisheye) const {
  if (vignetting == 0) return 1.0;
  const double theta = std::min(fisheye ? offAxisRad * 0.5 : offAxisRad, std::numbers::pi / 2);
  const double c = std::cos(theta);
  return 1.0 - vignetting * (1.0 - c * c * c * c);
}

CameraPhotometrics identityPhotometrics() { return {}; }

CameraPhotometrics randomPhotometrics(std::uint64_t seed, int index, double noiseSigma,
                                      bool drift) {
  HashRng rng(seed, kParameterStream * 1000 + static_cast<std::uint64_t>(index));
  CameraPhotometrics p;
  p.gain = rng.uniform(0.7, 1.3);
  for (int c = 0; c < 3; ++c) p.whiteBalance[c] = rng.uniform(0.85, 1.15);
  p.gamma = rng.uniform(0.9, 1.1);
  p.vignetting = rng.uniform(0.1, 0.4);
  p.noiseSigma = noiseSigma;
  // Drawn even when drift is off, so that --no-drift changes nothing else.
  const double amplitude = rng.uniform(0.05, 0.1);
  const double period = rng.uniform(6, 12);
  const double phase = rng.uniform(0, 2 * std::numbers::pi);
  if (drift) {
    p.driftAmplitude = amplitude;
    p.driftPeriodS = period;
    p.driftPhaseRad = phase;
  }
  return p;
}

CameraPhotometrics extremePhotometrics(std::uint64_t seed, int index, double noiseSigma, bool drift,
                                       bool source) {
  CameraPhotometrics p = randomPhotometrics(seed, index, noiseSigma, drift);
  p.gain = source ? 0.7 : 1.3;
  p.whiteBalance = source ? cv::Vec3d(0.85, 1.0, 1.15) : cv::Vec3d(1.15, 1.0, 0.85);  // B, G, R
  return p;
}

PhotometricCamera::PhotometricCamera(const CameraPhotometrics& parameters, std::uint64_t seed,
                                     int index, const cv::Mat& offAxisAngle, bool fisheye)
    : parameters_(parameters),
      seed_(seed),
      index_(index),
      vignette_(offAxisAngle.size(), CV_32F),
      noiseSigma_(static_cast<float>(parameters.noiseSigma)) {
  for (int r = 0; r < offAxisAngle.rows; ++r) {
    const float* angle = offAxisAngle.ptr<float>(r);
    float* v = vignette_.ptr<float>(r);
    for (int c = 0; c < offAxisAngle.cols; ++c) {
      v[c] = angle[c] < 0 ? 0.0f : static_cast<float>(parameters_.vignetteAt(angle[c], fisheye));
    }
  }
  if (parameters_.gamma != 1.0) {
    // pow() per channel per pixel would cost more than the whole ray cast; a table at 1/16 level
    // is exact to well under a level.
    gammaLut_.resize(kLutSize + 1);
    for (int i = 0; i <= kLutSize; ++i) {
      const double x = static_cast<double>(i) / kLutSteps / 255.0;
      gammaLut_[static_cast<std::size_t>(i)] =
          static_cast<float>(255.0 * std::pow(x, parameters_.gamma));
    }
  }
}

PhotometricCamera::Frame PhotometricCamera::frame(int frameIndex, double seconds) const {
  const double exposure = parameters_.gain * parameters_.exposureAt(seconds);
  Frame f;
  for (int c = 0; c < 3; ++c) {
    f.channelGain[c] = static_cast<float>(exposure * parameters_.whiteBalance[c]);
  }
  f.noiseKey = hash64(seed_, kNoiseStream, static_cast<std::uint64_t>(index_),
                      static_cast<std::uint64_t>(frameIndex));
  return f;
}

void PhotometricCamera::convertRow(const Frame& frame, const cv::Vec3f* radiance, cv::Vec3b* out,
                                   int row, int col, int count) const {
  const float* vignette = vignette_.ptr<float>(row) + col;
  const float* lut = gammaLut_.empty() ? nullptr : gammaLut_.data();
  const int pixelIndex = row * vignette_.cols + col;
  constexpr float kMaxX = static_cast<float>(kLutSize) / kLutSteps - 0.1f;
  const float* gaussian = gaussianTable().data();
  constexpr std::uint64_t kMask = (1U << kGaussianBits) - 1;
  for (int i = 0; i < count; ++i) {
    const float v = vignette[i];
    if (v == 0) {  // outside the lens: black, as a real fisheye's corners are
      out[i] = cv::Vec3b(0, 0, 0);
      continue;
    }
    // SplitMix64 on the pixel counter: independent per (frame key, pixel), 12 bits per channel.
    const std::uint64_t bits =
        noiseSigma_ > 0 ? mix64(frame.noiseKey +
                                static_cast<std::uint64_t>(pixelIndex + i) * 0x9e3779b97f4a7c15ULL)
                        : 0;
    for (int c = 0; c < 3; ++c) {
      float x = std::min(radiance[i][c] * frame.channelGain[c] * v, kMaxX);
      // x >= 0, so adding a half and truncating rounds.
      if (lut != nullptr)
        x = lut[static_cast<int>(x * kLutSteps + 0.5f)];  // NOLINT(bugprone-incorrect-roundings)
      if (noiseSigma_ > 0) x += noiseSigma_ * gaussian[(bits >> (kGaussianBits * c)) & kMask];
      out[i][c] = cv::saturate_cast<uchar>(x);  // rounds to nearest and clamps
    }
  }
}

}  // namespace surroundd::synth
