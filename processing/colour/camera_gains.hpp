#pragma once
// One gain per camera and channel applied to a picture stitched through a LUT: each pixel takes
// its camera's gains, a seam band's pixel its two cameras' harmonic mix in the band's proportion
// (what takes the band to the level both cameras agree on after their gains).
// What global gain compensation and the colour balance before the Poisson field both apply.

#include <span>

#include <opencv2/core.hpp>

#include "processing/stitch/panorama_lut.hpp"

namespace surroundd {
class WorkPool;
}

namespace surroundd::processing {

// `picture`: 8-bit BGR of lut.size, stitched through `lut` (the panorama's, or a view's) from the
// frames the gains were fitted to; `gains`: B G R per camera of the LUT.
void applyCameraGains(cv::Mat& picture, const PanoramaLut& lut, std::span<const cv::Vec3f> gains,
                      WorkPool& pool);

}  // namespace surroundd::processing
