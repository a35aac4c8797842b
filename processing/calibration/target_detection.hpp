#pragma once
// Finding printed targets in an image: checkerboards (inner corners, sub-pixel) and ArUco markers.
//
// Corner order follows processing/calibration/calibration_targets.hpp: a checkerboard's corners
// come row by row from inner corner (0, 0), whatever way round the board lies in the image, so that
// the same physical corner always gets the same index; an ArUco marker's corners come clockwise
// from its top left. Targets are assumed to be seen from their printed side.

#include <array>
#include <optional>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::processing {

// Inner corners of one board of this pattern; nullopt when none is found. `gray` is CV_8U.
std::optional<std::vector<cv::Point2f>> findCheckerboard(const cv::Mat& gray,
                                                         cv::Size innerCorners);

// Sub-pixel corners of a grid of `grid` columns x rows (row by row), with the largest window that
// stays inside one square.
void refineCheckerboardCorners(const cv::Mat& gray, std::vector<cv::Point2f>& corners,
                               cv::Size grid);

// Every board of this pattern in the image, up to `maxCount` (each found one is painted over
// before looking again).
std::vector<std::vector<cv::Point2f>> findCheckerboards(const cv::Mat& gray, cv::Size innerCorners,
                                                        int maxCount);

// The distance between the two closest neighbouring corners of a board's grid (row by row,
// `inner` columns x rows): its smallest square as the image shows it, pixels.
double smallestGridStep(std::span<const cv::Point2f> corners, cv::Size inner);

// How much brighter a board's odd inner squares are than its even ones (square (i, j) between
// inner corners (i, j) and (i + 1, j + 1)), in grey levels: positive when the listing starts on a
// black square as the board's own order does, negative when it starts on a white one, and
// near zero for corners that are not a board.
float blackFirstScore(const cv::Mat& gray, std::span<const cv::Point2f> corners, cv::Size inner);

struct ArucoDetection {
  int id = 0;
  std::array<cv::Point2f, 4> corners;
};
std::vector<ArucoDetection> findArucoMarkers(const cv::Mat& gray, int dictionary);

}  // namespace surroundd::processing
