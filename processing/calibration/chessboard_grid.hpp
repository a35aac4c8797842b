#pragma once
// Checking the labels of a chessboard grid grown from part of a board.
//
// OpenCV's sector-based detector, asked for "a 4x4 block or larger" (CALIB_CB_LARGER), can grow
// its grid wrongly: past the board's last inner corners onto the board's outline (a row whose
// corners are where the outer squares meet the white margin), or across the board in strides that
// skip corners (every other column, or columns 8, 3, 1, 0 of a 9x6 board, on Debian's opencv-doc
// photographs). Either way corners get the wrong (column, row), and a solve with them is off by
// pixels. A correctly labelled grid has two properties that this checks in the picture itself:
// every corner is where four squares meet (its four diagonal neighbourhoods alternate dark and
// light), and every cell between four neighbouring corners is one square (one colour throughout).

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::processing {

struct ChessboardGrid {
  std::vector<cv::Point2f> corners;  // row by row
  cv::Size size;                     // columns x rows
};

// `grid` with its outer rows and columns cut off while most of their corners are not chessboard
// corners (a grid grown onto the board's outline); nullopt when what is left still has corners or
// cells that are not a chessboard's (labels that skip corners), or is smaller than 2x2.
// `gray`: CV_8U.
std::optional<ChessboardGrid> checkedChessboardGrid(const cv::Mat& gray, ChessboardGrid grid);

}  // namespace surroundd::processing
