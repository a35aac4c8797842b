#pragma once
// The look-up table of a view that does not move (top, 360, an orbit pose held still): for each
// pixel of the view's picture, the camera taps that give what the renderer shows there, so one
// gather from the camera frames makes the picture, with no panorama, no upload and no read-back.
//
// It composes the panorama's LUT with where each view pixel samples the panorama, sampled as the
// renderer samples its panorama texture (bilinear, azimuth wrapping around, elevation clamped to
// the edge): the four panorama pixels' taps are merged per camera, a camera's share being its
// bilinear-weighted share over the four and its position the weighted mean of its positions among
// them (the panorama's unseen colour counts as one more camera); the two with the largest shares
// make the view pixel's primary and blend taps. A camera's position moves smoothly from one
// panorama pixel to the next, so one bilinear camera sample stands for the renderer's four samples
// of four. The renderer's picture is the blurrier where the panorama is coarser than the cameras
// (it blurs twice); with a panorama fine enough not to, the two agree within PSNR 40 dB.
//
// The result is a PanoramaLut of the view's size (its pixels are the view's, not the panorama's),
// applied by the Stitcher like the panorama's.

#include <opencv2/core.hpp>

#include "processing/stitch/panorama_lut.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::processing {

// `panoramaPositions`: CV_32FC2 of the view's size, each pixel's position in the panorama in its
// pixels (centres at integers, as PanoramaGeometry), NaN where the view shows no panorama (the car,
// the background); those pixels are unseen in the result. Throws std::invalid_argument for another
// type. Built row-parallel on `pool`.
PanoramaLut composeViewLut(const PanoramaLut& panorama, const cv::Mat& panoramaPositions,
                           WorkPool& pool);

}  // namespace surroundd::processing
