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
//   misalignment  processing/calibration/seam_misalignment.hpp: the shift between the two
//                 cameras' pictures of the ground under the seam, in centimetres;
//   brightness    the panorama's mean level.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/seam_misalignment.hpp"
#include "processing/stitch/panorama_lut.hpp"

namespace surroundd::bench {

using processing::SeamLine;
using processing::seamLines;

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

// Mean level (mean of the channels) over the pixels some camera sees.
double meanLevel(const cv::Mat& panorama, const processing::PanoramaLut& lut);

// How far apart the cameras' tints are: each camera's mean CIE a* and b* over the panorama's
// ground it owns (the rows below the horizon, `settings`), and the standard deviation of those
// means across the cameras (the root of a*'s and b*'s variances' sum), in L*a*b* units.
double chromaSpread(const cv::Mat& panorama, const processing::PanoramaLut& lut,
                    const processing::PanoramaSettings& settings);

}  // namespace surroundd::bench
