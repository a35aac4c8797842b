// The label check on chessboard grids grown from part of a board
// (processing/calibration/chessboard_grid): on a rendered 9x6 board, a correct grid and any part of
// it pass whole; a grid grown a row past the board onto its outline is cut back to the board; grids
// that skip corners (every other column, or columns 8, 3, 1, 0 as OpenCV grew one on an opencv-doc
// photograph) are refused.

#include "processing/calibration/chessboard_grid.hpp"

#include <numeric>

#include <gtest/gtest.h>

#include "tests/calibration/board_views_support.hpp"

namespace surroundd::calibration::testing {
namespace {

using processing::ChessboardGrid;

// Corner (column, row) of a grid `width` columns wide, listed row by row.
std::size_t index(int column, int row, int width) {
  return static_cast<std::size_t>(row) * static_cast<std::size_t>(width) +
         static_cast<std::size_t>(column);
}

struct RenderedBoard {
  cv::Mat gray;
  ChessboardGrid board;  // 9x6, row by row; empty when the board was not found whole
};

// One rendered board for every test (a render takes about a second).
const RenderedBoard& renderedBoard() {
  static const RenderedBoard kRendered = [] {
    RenderedBoard rendered;
    const auto lens = presetCameras("paper.yaml").front().intrinsics;
    rendered.gray = toGray(anyBoardViews(lens, chessboard(9, 6), 1, 31).front());
    const auto found = processing::findBoard(rendered.gray, chessboard(9, 6));
    if (found.outcome != processing::BoardSearch::Outcome::kFound || found.corners.size() != 54) {
      return rendered;
    }
    rendered.board = {found.corners, found.seenGrid};
    if (found.seenGrid.width < found.seenGrid.height) {  // listed column by column: the same grid
      rendered.board = {{}, {found.seenGrid.height, found.seenGrid.width}};
      rendered.board.corners.reserve(found.corners.size());
      for (int row = 0; row < rendered.board.size.height; ++row) {
        for (int column = 0; column < rendered.board.size.width; ++column) {
          rendered.board.corners.push_back(found.corners[index(row, column, found.seenGrid.width)]);
        }
      }
    }
    return rendered;
  }();
  return kRendered;
}

class ChessboardGridCheck : public ::testing::Test {
 protected:
  void SetUp() override {
    gray_ = renderedBoard().gray;
    board_ = renderedBoard().board;
    ASSERT_EQ(board_.size, cv::Size(9, 6)) << "the rendered board was not found whole";
  }

  cv::Point2f at(int column, int row) const {
    return board_.corners[index(column, row, board_.size.width)];
  }

  // The board's corners of these columns and rows, relabelled 0, 1, 2, ... each way.
  ChessboardGrid pick(const std::vector<int>& columns, const std::vector<int>& rows) const {
    ChessboardGrid grid{{}, {static_cast<int>(columns.size()), static_cast<int>(rows.size())}};
    grid.corners.reserve(columns.size() * rows.size());
    for (const int row : rows) {
      for (const int column : columns) grid.corners.push_back(at(column, row));
    }
    return grid;
  }

  static std::vector<int> upTo(int count) {
    std::vector<int> all(static_cast<std::size_t>(count));
    std::iota(all.begin(), all.end(), 0);
    return all;
  }

  cv::Mat gray_;
  ChessboardGrid board_;
};

TEST_F(ChessboardGridCheck, TheWholeBoardAndAnyPartOfItPassWhole) {
  const auto whole = processing::checkedChessboardGrid(gray_, board_);
  ASSERT_TRUE(whole);
  EXPECT_EQ(whole->size, board_.size);
  EXPECT_EQ(whole->corners, board_.corners);
  const auto part = pick({2, 3, 4, 5, 6}, {1, 2, 3, 4});
  const auto checked = processing::checkedChessboardGrid(gray_, part);
  ASSERT_TRUE(checked);
  EXPECT_EQ(checked->size, part.size);
}

TEST_F(ChessboardGridCheck, AGridGrownOntoTheBoardsOutlineIsCutBackToTheBoard) {
  // One more row and one more column, a square beyond the last inner corners: where the outer
  // squares meet the white margin.
  const int w = board_.size.width, h = board_.size.height;
  ChessboardGrid grown{{}, {w + 1, h + 1}};
  const auto beyond = [](cv::Point2f last, cv::Point2f before) { return 2 * last - before; };
  for (int row = 0; row <= h; ++row) {
    for (int column = 0; column <= w; ++column) {
      const auto inRow = [&](int c) {
        return row < h ? at(c, row) : beyond(at(c, h - 1), at(c, h - 2));
      };
      grown.corners.push_back(column < w ? inRow(column) : beyond(inRow(w - 1), inRow(w - 2)));
    }
  }
  const auto checked = processing::checkedChessboardGrid(gray_, grown);
  ASSERT_TRUE(checked);
  EXPECT_EQ(checked->size, board_.size);
  EXPECT_EQ(checked->corners, board_.corners);
}

TEST_F(ChessboardGridCheck, GridsThatSkipCornersAreRefused) {
  const auto rows = upTo(board_.size.height);
  EXPECT_FALSE(processing::checkedChessboardGrid(gray_, pick({0, 2, 4, 6, 8}, rows)));
  EXPECT_FALSE(processing::checkedChessboardGrid(gray_, pick({0, 1, 3, 8}, rows)));
  EXPECT_FALSE(processing::checkedChessboardGrid(gray_, pick(upTo(9), {0, 2, 4})));
}

TEST_F(ChessboardGridCheck, AMalformedGridIsRefused) {
  ChessboardGrid malformed = board_;
  malformed.corners.pop_back();
  EXPECT_FALSE(processing::checkedChessboardGrid(gray_, malformed));
}

}  // namespace
}  // namespace surroundd::calibration::testing
