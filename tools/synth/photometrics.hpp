#pragma once
// What each synthetic camera does to the light before it becomes an 8-bit pixel:
//
//   x     = L_c * gain * whiteBalance_c * exposure(t) * vignette(pixel)      (L: scene radiance,
//   0..255) value = clamp(round(255 * (min(x, 511.9) / 255)^gamma + N(0, noiseSigma^2)), 0, 255)
//   exposure(t) = 1 + driftAmplitude * sin(2 pi t / driftPeriod + driftPhase)
//   vignette    = 1 - vignetting * (1 - cos^4(theta')), theta' = the ray's angle off the optical
//                 axis (halved for a fisheye, whose lens compensates much of the natural falloff)
//
// Identity (all neutral, no noise, no drift, no vignetting) gives value = round(clamp(L)): the
// ground truth's noise-free camera images. Noise is a pure function of (seed, camera, frame, pixel,
// channel), so frames do not depend on thread scheduling.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::synth {

struct CameraPhotometrics {
  double gain = 1;                  // 0.7 .. 1.3 when random
  cv::Vec3d whiteBalance{1, 1, 1};  // B, G, R multipliers, 0.85 .. 1.15
  double gamma = 1;                 // 0.9 .. 1.1
  double vignetting = 0;            // strength, 0 .. 0.4
  double noiseSigma = 0;            // 8-bit levels
  double driftAmplitude = 0;        // relative, up to 0.1 (+-10 %)
  double driftPeriodS = 0;          // 6 .. 12 s
  double driftPhaseRad = 0;

  double exposureAt(double seconds) const;
  double vignetteAt(double offAxisRad, bool fisheye) const;
  bool operator==(const CameraPhotometrics&) const = default;
};

CameraPhotometrics identityPhotometrics();
// Random parameters for camera `index`, deterministic from the seed.
CameraPhotometrics randomPhotometrics(std::uint64_t seed, int index, double noiseSigma, bool drift);
// The random parameters with gain and white balance at the ends of their ranges: dark and warm for
// a colour-correction source, bright and cool for a target.
CameraPhotometrics extremePhotometrics(std::uint64_t seed, int index, double noiseSigma, bool drift,
                                       bool source);

// The per-camera part that does not change from frame to frame (gamma table, vignette image), and
// the per-pixel conversion. One per camera, built before the first frame.
class PhotometricCamera {
 public:
  // `offAxisAngle`: CV_32F, each pixel's ray angle off the optical axis, negative outside the lens
  // (those pixels stay black, without noise).
  PhotometricCamera(const CameraPhotometrics& parameters, std::uint64_t seed, int index,
                    const cv::Mat& offAxisAngle, bool fisheye);

  // Frame-constant state, computed once per frame.
  struct Frame {
    cv::Vec3f channelGain;
    std::uint64_t noiseKey = 0;
  };
  Frame frame(int frameIndex, double seconds) const;

  // Converts `count` pixels of radiance starting at (row, col) to 8-bit BGR.
  void convertRow(const Frame& frame, const cv::Vec3f* radiance, cv::Vec3b* out, int row, int col,
                  int count) const;

  const CameraPhotometrics& parameters() const { return parameters_; }

 private:
  static constexpr int kLutSteps = 16;  // table entries per 8-bit level
  static constexpr int kLutSize = 512 * kLutSteps;

  CameraPhotometrics parameters_;
  std::uint64_t seed_;
  int index_;
  cv::Mat vignette_;             // CV_32F: the vignette factor, 0 outside the lens
  std::vector<float> gammaLut_;  // empty when gamma == 1
  float noiseSigma_;
};

}  // namespace surroundd::synth
