#pragma once
// How well a panorama LUT matches the world it was built for.
//
// Seam alignment is geometric and exact: at every seam pixel that both neighbours sample, each
// camera's sample position is cast back onto the true ground (z = 0) through that camera's lens
// and pose; the two ground points, seen from the panorama centre, should fall on one panorama
// pixel. Their distance in panorama pixels is the misalignment a viewer sees as a doubled or
// broken lane marking. Image error compares a stitched panorama with the generator's true one,
// over the pixels where the true scene is ground inside the bowl's floor.

#include <opencv2/core.hpp>

#include "processing/stitch/panorama_lut.hpp"
#include "tools/bench/recording_truth.hpp"
#include "tools/synth/scene.hpp"

namespace surroundd::bench {

struct SeamAlignment {
  double meanPx = 0;
  double maxPx = 0;
  int samples = 0;  // seam pixels on the ground that both cameras sample
};

SeamAlignment measureGroundSeams(const processing::Rig& rig,
                                 const processing::PanoramaSettings& settings,
                                 const processing::PanoramaLut& lut);

// CV_8U, 255 where the ray from the panorama centre first meets the ground (no box or wall in
// front) within the bowl's floor radius, with the vehicle at `pose` in the recording's scene.
cv::Mat trueGroundMask(const synth::Scene& scene, const synth::VehiclePose& pose,
                       const processing::PanoramaSettings& settings);

// The colour step across the seams of a panorama, 8-bit levels: at each seam (the bisector
// columns of the LUT, where the primary camera changes) and every band of `window` rows that lies
// inside `mask` (CV_8U; e.g. the true ground, where the two cameras see the same thing) on both
// sides, the mean colours of two `window`-wide column strips just outside the blend band, one on
// each side, are compared; the result is the mean absolute difference over bands and channels.
// Scene detail averages out over the strips; what remains is the cameras' disagreement.
double seamColourStep(const cv::Mat& panorama, const processing::PanoramaLut& lut,
                      double featherRad, const cv::Mat& mask, int window = 8);

// The colour mismatch across the seams, 8-bit levels: over every `window` x `window` tile of the
// panorama that a source camera owns within `reach` pixels of a seam with a target camera, that
// the target camera sees too and that lies in `mask` (the true ground: the same surface for
// both), the mean colour of the panorama against the mean of the target camera's own samples;
// the mean absolute difference over tiles and channels. Tiles average the sensor noise away; what
// remains is the step a viewer sees at the seam.
double seamColourError(const cv::Mat& panorama, const std::vector<cv::Mat>& frames,
                       const processing::Rig& rig, const processing::PanoramaSettings& settings,
                       const processing::PanoramaLut& lut, const cv::Mat& mask, int window = 4,
                       int reach = 12);

// The camera images as a global correction leaves them (per camera and channel gains): what the
// seams of a gain-compensated panorama are measured against, as its targets change too.
std::vector<cv::Mat> framesWithGains(const std::vector<cv::Mat>& frames,
                                     const std::vector<cv::Vec3f>& gains);

// Mean absolute difference over the mask and the channels, 8-bit levels.
double meanAbsoluteError(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask);

}  // namespace surroundd::bench
