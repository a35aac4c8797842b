#pragma once
// The linear system of Poisson local colour correction for one source region (DESIGN.md §2.3).
//
// The region's pixels, at the correction scale, are the unknowns c_p (one value per colour
// channel). With Laplace's equation inside the region, a Dirichlet condition c = I_target -
// I_source on pixels across a seam with a target camera and a Neumann condition (no flux) on every
// other border, the 5-point stencil gives, for each unknown p,
//
//     degree(p) * c_p - sum over unknown neighbours q of c_q = sum over Dirichlet neighbours of d
//
// where degree(p) counts the neighbours that are unknowns or Dirichlet pixels. The matrix depends
// only on the geometry: it is built once; per frame only the right-hand side changes. It is
// symmetric positive definite when every connected part of the region touches a Dirichlet pixel
// (the domain builder leaves out parts that do not).

#include <span>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::processing {

struct PoissonSystem {
  // Unknown i sits at pixels[i] in the region's own frame: x from 0 to size.width - 1, across the
  // +-180 degree column without a break, y from 0 at the region's top row. Row-major order.
  cv::Size size;
  std::vector<cv::Point> pixels;
  std::vector<int> degree;                 // per unknown: neighbours that are unknowns or Dirichlet
  std::vector<std::pair<int, int>> links;  // unknown 4-neighbours (i < j), each pair once

  std::size_t unknowns() const { return pixels.size(); }
};

// Right-hand sides and solutions: three channels per unknown, interleaved (index 3 * i + c).
using ChannelValues = std::vector<float>;

}  // namespace surroundd::processing
