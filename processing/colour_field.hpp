#pragma once
// A colour correction as a stitcher applies it, whoever computed it: a grid of blocks of `block` x
// `block` panorama pixels, each holding what the correction does at a pixel of 255 (a gain minus
// one, or an offset), upsampled between blocks, and per panorama pixel the share (0..256) of it
// that applies there (256 inside a corrected region, less across its seam band). The Poisson
// correction (processing/colour/) yields one; the GPU stitcher (render/) takes one, so that the
// renderer needs nothing of how it was solved.

#include <cstdint>
#include <span>

#include <opencv2/core.hpp>

namespace surroundd::processing {

struct ColourField {
  // CV_32FC3, the block grid: borrowed from its correction, which updates it in place each set.
  const cv::Mat* values = nullptr;
  // Per panorama pixel, row by row. Borrowed: valid while its correction's cameras stay the same.
  std::span<const std::uint16_t> shares;
  int block = 4;          // pixels a block side
  bool additive = false;  // values are offsets in levels; otherwise gains (value / 255 + 1)
  // Per camera, B G R gains every pixel takes before the field (a global balance), as
  // applyCameraGains() (processing/colour/camera_gains.hpp) applies them; empty: none. Borrowed,
  // updated in place each set.
  std::span<const cv::Vec3f> cameraGains;
};

}  // namespace surroundd::processing
