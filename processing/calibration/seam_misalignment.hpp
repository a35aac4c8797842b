#pragma once
// How far apart two neighbouring cameras put the same ground, as their calibration projects it:
// phase correlation of each camera's own picture of a 1.6 m ground patch under the seam between
// them (1 cm a pixel; the nearest of 25, 18, 12, 8 and 5 degrees below the panorama's centre that
// both see past the body), read as a shift in centimetres with the correlation's peak response.
// A sound calibration gives a few millimetres; a camera knocked by 1 degree moves the ground under
// both its seams by the patch's distance times the angle (7 cm at 4 m). Used by the benchmark's
// per-seam report and by the daemon's calibration-drift watch.
//
// Errors: none thrown; a seam whose patch either camera cannot see has no probe.

#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/rig.hpp"
#include "processing/stitch/panorama_lut.hpp"

namespace surroundd::processing {

struct SeamLine {
  std::size_t left = 0, right = 0;  // cameras: left of the seam is at larger azimuth
  double azimuthRad = 0;
  std::string name;  // "front/left"
};

// The seams of a rig's panorama: bisectors between neighbouring cameras' axes, as the LUT puts
// them.
std::vector<SeamLine> seamLines(const Rig& rig, const PanoramaSettings& settings);

struct SeamMisalignment {
  double distanceM = 0;  // of the patch from the vehicle's centre
  double shiftCm = 0;
  // Where the right camera puts the ground the left one puts at the patch's centre, from there:
  // vehicle frame, metres.
  cv::Vec2d shiftM;
  double response = 0;  // phase correlation peak, 0..1: under ~0.05 the shift means little
};

// One seam's patch, set up once: where each camera sees it. measure() then takes a frame set's
// two pictures and allocates nothing after its first call.
class SeamMisalignmentProbe {
 public:
  // None where either camera sees under 80 % of every patch (body, image edge).
  static std::optional<SeamMisalignmentProbe> make(const Rig& rig, const PanoramaSettings& settings,
                                                   const SeamLine& seam);
  // The patch centred on `centre` (ground, vehicle frame), `side` pixels of `pixelM` metres; none
  // where either camera sees under 80 % of it.
  static std::optional<SeamMisalignmentProbe> at(const Rig& rig, const SeamLine& seam,
                                                 const cv::Point2d& centre, int side,
                                                 double pixelM);

  // `left` and `right`: the seam's cameras' pictures, 8-bit BGR of their lenses' sizes.
  SeamMisalignment measure(const cv::Mat& left, const cv::Mat& right);

  const SeamLine& seam() const { return seam_; }
  double distanceM() const { return distanceM_; }
  const cv::Point2d& centre() const { return centre_; }
  double sideM() const { return window_.cols * pixelM_; }
  double pixelM() const { return pixelM_; }

 private:
  SeamLine seam_;
  double distanceM_ = 0;
  cv::Point2d centre_;
  double pixelM_ = 0;
  std::array<cv::Mat, 2> mapX_, mapY_;    // per side: ground patch -> the camera's picture
  std::array<cv::Mat, 2> seen_, unseen_;  // per side: where it sees the patch, and not
  std::array<cv::Mat, 2> colour_, grey_, patch_;
  cv::Mat window_;
};

// make() then measure() on `frames` (one picture per camera of the rig).
std::optional<SeamMisalignment> seamMisalignment(const Rig& rig, std::span<const cv::Mat> frames,
                                                 const PanoramaSettings& settings,
                                                 const SeamLine& seam);

}  // namespace surroundd::processing
