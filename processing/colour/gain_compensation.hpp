#pragma once
// The baseline colour correction: one gain per camera and channel, the least-squares fit that
// makes overlapping cameras agree (Brown & Lowe's gain compensation), applied to each camera's
// share of every panorama pixel. Global gains cannot follow vignetting or local light, which is
// what Poisson local correction is compared against.
//
// On real rigs the overlaps hold parallax, objects and clipped pixels, so each camera's level in
// an overlap is the median of its usable samples, not the mean. The fit then keeps the rig's
// brightness (least squares alone sinks towards dimmer pictures, to gains of 0.02 on a real rig):
// the gains are scaled so that the median camera's is 1, and each stays within [minGain, maxGain],
// said once per camera in notesOfLastUpdate() when the bound bites.

#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "common/pixel_format.hpp"
#include "processing/stitch/panorama_lut.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::processing {

class GainCompensation {
 public:
  // Borrows the LUT and the pool. Camera names are for the notes (default: their indices).
  GainCompensation(const PanoramaLut& lut, WorkPool& pool, double minGain = 0.5,
                   double maxGain = 2.0, std::vector<std::string> cameraNames = {});

  // Fits the gains to the overlaps of this frame set, held in `format` (common/pixel_format.hpp;
  // an empty Mat: that camera is missing; its gain stays as it was).
  void update(std::span<const cv::Mat> frames, PixelFormat format = PixelFormat::kBgr);
  // Multiplies each camera's share of every pixel of a panorama stitched from the same frames.
  void apply(cv::Mat& panorama) { apply(panorama, lut_); }
  // The same for a picture made through another LUT of this rig's cameras from the same frames (a
  // fixed view's: processing/stitch/view_lut.hpp).
  void apply(cv::Mat& picture, const PanoramaLut& lut);

  const std::vector<cv::Vec3f>& gains() const { return gains_; }
  const std::vector<std::string>& notesOfLastUpdate() const { return notes_; }

 private:
  const PanoramaLut& lut_;
  WorkPool& pool_;
  std::vector<BlendTap> overlap_;  // every few blend pixels: the owner's tap, then the other's
  std::vector<LutTap> overlapOwner_;
  std::vector<std::string> names_;
  double minGain_, maxGain_;
  std::vector<cv::Vec3f> gains_;
  // Per camera pair (i * n + j) and channel: a histogram of camera i's levels where it overlaps j.
  std::vector<std::array<int, 256>> histograms_;
  std::vector<double> counts_;
  std::vector<double> sorted_;  // the gains of one channel, for their median
  std::vector<std::uint8_t> saidClamped_;
  std::vector<std::string> notes_;
};

}  // namespace surroundd::processing
