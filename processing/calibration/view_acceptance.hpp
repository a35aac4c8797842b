#pragma once
// Whether a found view is worth solving with, judged before the solve: a blurred picture moves
// its corners along the blur, and a view that repeats another adds weight without information
// (two copies of one picture count it twice against every other view).

#include <cstddef>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/calibration/calibration_board.hpp"

namespace surroundd::processing {

// How wide the board's edges are in the picture, pixels: over the edges between neighbouring
// corners, the median of (brightest - darkest) / steepest slope across the edge. About 1 for a
// sharp picture, 2.5 sigma for one blurred by a Gaussian of sigma pixels.
double edgeWidthPx(const cv::Mat& gray, const BoardView& view);

// The middle value of a view's measures (the upper of the two middle ones); 0 for none.
double median(std::vector<double> values);

// The board's squares in the picture, pixels: the median distance between neighbouring corners.
double squareSizePx(const BoardView& view);

struct DuplicateView {
  std::size_t view;    // index of the repeat
  std::size_t of;      // index of the earlier view it repeats
  double overlap = 0;  // of the two boards' outlines: intersection over union
};

// A view whose board outline overlaps an earlier view's by at least `minOverlap` (intersection
// over union) shows the board where it already was: a copy, or a picture taken without moving.
std::vector<DuplicateView> findDuplicateViews(std::span<const BoardView> views,
                                              double minOverlap = 0.95);

}  // namespace surroundd::processing
