#pragma once
// The board a lens is calibrated with, and finding it in one picture, whole or in part.
//
// For intrinsics only the board's grid matters: every view gets a pose of its own, so a view's
// corners are labelled by their (column, row) on a grid of unit squares, with any origin. A board
// cut off at the image edge, a square board whose two ends look alike, or a grid listed turned or
// mirrored all give the same lens (a mirrored plane is the same plane seen from behind). Which end
// is which matters only where a pose must be unambiguous (extrinsics: calibration_targets.hpp).

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace surroundd::processing {

enum class BoardKind { kChessboard, kCharuco };

struct CalibrationBoard {
  BoardKind kind = BoardKind::kChessboard;
  // Chessboard: inner corners (where four squares meet), columns x rows. ChArUco: squares.
  cv::Size size;
  int arucoDictionary = 0;      // ChArUco: cv::aruco::PREDEFINED_DICTIONARY_NAME
  double markerToSquare = 0.7;  // ChArUco: a marker's side over a square's

  // Columns x rows of the corners a whole view shows.
  cv::Size innerCorners() const;
  // "9x6 chessboard", "8x6-square ChArUco board (4x4_50)": for messages.
  std::string describe() const;
};

// The board as found in one picture.
struct BoardView {
  std::string name;                  // for reports, e.g. the image file
  std::vector<cv::Point2f> corners;  // pixels, sub-pixel refined
  std::vector<cv::Point> grid;       // each corner's (column, row) on the board's grid
  double edgeWidthPx = 0;            // how blurred its edges are (view_acceptance.hpp); 0: unknown
};

// Fewer corners than this in a view, or all of them on one line, pin nothing down.
inline constexpr int kMinimumViewCorners = 9;

struct BoardSearch {
  // kLargerThanBoard: a chessboard grid wider or taller than the board the user named, which
  // means the named size is wrong (a grid is never found larger than the print).
  enum class Outcome { kFound, kNotFound, kLargerThanBoard };
  Outcome outcome = Outcome::kNotFound;
  std::vector<cv::Point2f> corners;
  std::vector<cv::Point> grid;
  cv::Size seenGrid;  // columns x rows of the grid found (chessboard), for messages
};

// Looks for `board` in `gray` (CV_8U). A chessboard seen only in part is found when at least a
// 4x4 block of its corners (or the whole board, if smaller) is in view; a grid grown from such a
// block is checked in the picture and cut back or dropped where it went past the board or skipped
// corners (chessboard_grid.hpp), and when it is not the whole board, the whole board is looked
// for as such. May take seconds on a large picture with no board in it (searchPictures() bounds
// that).
BoardSearch findBoard(const cv::Mat& gray, const CalibrationBoard& board);

}  // namespace surroundd::processing
