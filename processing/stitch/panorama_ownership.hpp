#pragma once
// Which camera owns which panorama pixels, as runs along the rows, built once from the LUT: to
// mark a faulty camera's part of the panorama (and so of every view made from it) while the
// other cameras' parts stay as they are.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/stitch/panorama_lut.hpp"

namespace surroundd::processing {

class PanoramaOwnership {
 public:
  explicit PanoramaOwnership(const PanoramaLut& lut);

  // Greys out the pixels `camera` owns, with dark diagonal stripes over them: "this camera is not
  // to be trusted". `panorama` is 8-bit BGR of the LUT's size.
  void markFaulty(cv::Mat& panorama, std::size_t camera) const;

 private:
  struct Run {
    std::uint16_t row;
    std::uint16_t begin;
    std::uint16_t end;  // one past the last column
  };
  std::vector<std::vector<Run>> runs_;  // per camera
};

}  // namespace surroundd::processing
