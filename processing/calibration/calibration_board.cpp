#include "processing/calibration/calibration_board.hpp"

#include <algorithm>
#include <set>

#include <fmt/format.h>
#include <opencv2/aruco/charuco.hpp>
#include <opencv2/calib3d.hpp>

#include "processing/calibration/calibration_targets.hpp"
#include "processing/calibration/chessboard_grid.hpp"
#include "processing/calibration/target_detection.hpp"

namespace surroundd::processing {
namespace {

// A part this small of a chessboard is still told apart from other textures by the
// sector-based detector; smaller parts are found in tiles, windows and keyboards too.
constexpr int kPartialBlock = 4;

bool fits(cv::Size grid, cv::Size board) {
  return (grid.width <= board.width && grid.height <= board.height) ||
         (grid.width <= board.height && grid.height <= board.width);
}

// Enough corners, spread over at least two rows and two columns: a homography needs them.
bool spansAPlane(const std::vector<cv::Point>& grid) {
  std::set<int> columns, rows;
  for (const auto& g : grid) columns.insert(g.x), rows.insert(g.y);
  return static_cast<int>(grid.size()) >= kMinimumViewCorners && columns.size() >= 2 &&
         rows.size() >= 2;
}

// The grid a chessboard search grew from a block of `block` x `block` corners (CALIB_CB_LARGER),
// its labels checked in the picture (chessboard_grid.hpp): as much of the board as is in view.
// A first pass without the exhaustive search is several times faster and finds most boards.
std::optional<ChessboardGrid> grownGrid(const cv::Mat& gray, int block) {
  ChessboardGrid grid;
  cv::Mat meta;
  const int flags = cv::CALIB_CB_NORMALIZE_IMAGE | cv::CALIB_CB_LARGER;
  if (!cv::findChessboardCornersSB(gray, {block, block}, grid.corners, flags, meta) &&
      !cv::findChessboardCornersSB(gray, {block, block}, grid.corners,
                                   flags | cv::CALIB_CB_EXHAUSTIVE, meta)) {
    return std::nullopt;
  }
  grid.size = {meta.cols, meta.rows};
  return checkedChessboardGrid(gray, std::move(grid));
}

// The whole board, by the detectors that look for exactly its size (row by row; which end is
// first does not matter here).
std::optional<ChessboardGrid> wholeBoard(const cv::Mat& gray, cv::Size inner) {
  ChessboardGrid grid{{}, inner};
  if (cv::findChessboardCornersSB(gray, inner, grid.corners, cv::CALIB_CB_NORMALIZE_IMAGE) ||
      cv::findChessboardCorners(gray, inner, grid.corners,
                                cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE)) {
    return grid;
  }
  return std::nullopt;
}

BoardSearch findChessboard(const cv::Mat& gray, const CalibrationBoard& board) {
  BoardSearch found;
  const cv::Size inner = board.innerCorners();
  auto grid = grownGrid(gray, std::min({kPartialBlock, inner.width, inner.height}));
  if (grid && !fits(grid->size, inner)) {
    found.seenGrid = grid->size;
    found.outcome = BoardSearch::Outcome::kLargerThanBoard;
    return found;
  }
  // A grown grid that is not the whole board (or none, or one whose labels were wrong) may be a
  // detector's miss on a board that is all there: the detectors for exactly its size find it.
  if (!grid || grid->size.area() < inner.area()) {
    if (auto whole = wholeBoard(gray, inner)) grid = std::move(whole);
  }
  if (!grid) return found;
  found.seenGrid = grid->size;
  refineCheckerboardCorners(gray, grid->corners, grid->size);
  for (int row = 0; row < grid->size.height; ++row) {
    for (int column = 0; column < grid->size.width; ++column) {
      found.grid.emplace_back(column, row);
    }
  }
  found.corners = std::move(grid->corners);
  found.outcome =
      spansAPlane(found.grid) ? BoardSearch::Outcome::kFound : BoardSearch::Outcome::kNotFound;
  return found;
}

BoardSearch findCharuco(const cv::Mat& gray, const CalibrationBoard& board) {
  BoardSearch found;
  const auto dictionary = cv::aruco::getPredefinedDictionary(board.arucoDictionary);
  const auto charuco =
      cv::aruco::CharucoBoard::create(board.size.width, board.size.height, 1.0f,
                                      static_cast<float>(board.markerToSquare), dictionary);
  std::vector<std::vector<cv::Point2f>> markerCorners;
  std::vector<int> markerIds;
  cv::aruco::detectMarkers(gray, dictionary, markerCorners, markerIds);
  if (markerIds.size() < 2) return found;
  // Each chessboard corner between two found markers, from the markers' local homography, then
  // refined on the image: any part of the board that shows two markers gives corners.
  std::vector<cv::Point2f> corners;
  std::vector<int> ids;
  cv::aruco::interpolateCornersCharuco(markerCorners, markerIds, gray, charuco, corners, ids);
  const int columns = board.size.width - 1;
  for (std::size_t i = 0; i < ids.size(); ++i) {
    found.grid.emplace_back(ids[i] % columns, ids[i] / columns);
  }
  found.corners = std::move(corners);
  found.seenGrid = board.innerCorners();
  found.outcome =
      spansAPlane(found.grid) ? BoardSearch::Outcome::kFound : BoardSearch::Outcome::kNotFound;
  return found;
}

}  // namespace

cv::Size CalibrationBoard::innerCorners() const {
  return kind == BoardKind::kChessboard ? size : cv::Size(size.width - 1, size.height - 1);
}

std::string CalibrationBoard::describe() const {
  if (kind == BoardKind::kChessboard) {
    return fmt::format("{}x{} chessboard", size.width, size.height);
  }
  return fmt::format("{}x{}-square ChArUco board ({})", size.width, size.height,
                     arucoDictionaryName(arucoDictionary));
}

BoardSearch findBoard(const cv::Mat& gray, const CalibrationBoard& board) {
  return board.kind == BoardKind::kChessboard ? findChessboard(gray, board)
                                              : findCharuco(gray, board);
}

}  // namespace surroundd::processing
