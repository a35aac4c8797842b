#pragma once
// What a driver sees at each seam of a stitched panorama, measured on any rig (real or generated,
// no ground truth needed; issue 15's figures):
//   colour step   the median colour of a 1.5 degree strip just past the blend band on each side
//                 of the seam, compared (mean over channels of the absolute difference, levels),
//                 on near ground (elevation -15..-35 deg) and far ground (-2..-12 deg): what a
//                 driver sees, content on either side included;
//   view step     the ground from one strip to the other (the blend band between them) seen by
//                 both cameras, each as its correction leaves it: the colour difference of one
//                 piece of ground between the two views (per 1 degree of elevation, median
//                 colours compared; averaged over the range), so the photometric step alone,
//                 without the content's change across the seam;
//   misalignment  phase correlation of the two cameras' own pictures of a 1.6 m ground patch
//                 under the seam (1 cm a pixel; the nearest of 25, 18, 12, 8 and 5 degrees below
//                 the panorama's centre that both see past the body), as their calibration projects
//                 it: the shift between them in centimetres, with the correlation's peak response;
//   brightness    the panorama's mean level.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/stitch/panorama_lut.hpp"

namespace surroundd::bench {

struct SeamLine {
  std::size_t left = 0, right = 0;  // cameras: left of the seam is at larger azimuth
  double azimuthRad = 0;
  std::string name;  // "front/left"
};

// The seams of a rig's panorama: bisectors between neighbouring cameras' axes, as the LUT puts
// them.
std::vector<SeamLine> seamLines(const processing::Rig& rig,
                                const processing::PanoramaSettings& settings);

struct SeamColourStep {
  std::optional<double> nearLevels, farLevels;  // nullopt: a strip with too few seen pixels
};

SeamColourStep seamColourStep(const cv::Mat& panorama, const processing::PanoramaLut& lut,
                              const processing::PanoramaSettings& settings, const SeamLine& seam);

// `raw` is the uncorrected panorama of `frames`, `corrected` the same with a correction applied
// (the raw one again for none). Each camera's correction is read off the panoramas as the ratio
// corrected / raw in its own strip, band by band, and applied to its own view of the ground.
SeamColourStep seamViewStep(const cv::Mat& raw, const cv::Mat& corrected,
                            const processing::PanoramaProjector& projector,
                            const processing::PanoramaLut& lut, std::span<const cv::Mat> frames,
                            const SeamLine& seam);

struct SeamAlignment {
  double distanceM = 0;  // of the patch from the vehicle's centre
  double shiftCm = 0;
  double response = 0;  // phase correlation peak, 0..1: under ~0.05 the shift means little
};

// nullopt where either camera sees under 80 % of every patch (body, image edge).
std::optional<SeamAlignment> seamAlignment(const processing::Rig& rig,
                                           std::span<const cv::Mat> frames,
                                           const processing::PanoramaSettings& settings,
                                           const SeamLine& seam);

// Mean level (mean of the channels) over the pixels some camera sees.
double meanLevel(const cv::Mat& panorama, const processing::PanoramaLut& lut);

}  // namespace surroundd::bench
