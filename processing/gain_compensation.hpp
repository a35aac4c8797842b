#pragma once
// The baseline colour correction: one gain per camera and channel, the least-squares fit that
// makes overlapping cameras agree (Brown & Lowe's gain compensation), applied to each camera's
// share of every panorama pixel. Global gains cannot follow vignetting or local light, which is
// what Poisson local correction is compared against.

#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/panorama_lut.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::processing {

class GainCompensation {
 public:
  // Borrows the LUT and the pool.
  GainCompensation(const PanoramaLut& lut, WorkPool& pool);

  // Fits the gains to the overlaps of this frame set (an empty Mat: that camera is missing; its
  // gain stays as it was).
  void update(std::span<const cv::Mat> frames);
  // Multiplies each camera's share of every pixel of a panorama stitched from the same frames.
  void apply(cv::Mat& panorama);

  const std::vector<cv::Vec3f>& gains() const { return gains_; }

 private:
  const PanoramaLut& lut_;
  WorkPool& pool_;
  std::vector<BlendTap> overlap_;  // every few blend pixels: the owner's tap, then the other's
  std::vector<LutTap> overlapOwner_;
  std::vector<cv::Vec3f> gains_;
  // Per camera pair (i * n + j): sum of camera i's values where it overlaps j, and the count.
  std::vector<cv::Vec3d> sums_;
  std::vector<double> counts_;
};

}  // namespace surroundd::processing
