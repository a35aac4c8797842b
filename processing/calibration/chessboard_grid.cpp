#include "processing/calibration/chessboard_grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <opencv2/imgproc.hpp>

namespace surroundd::processing {
namespace {

// Where a corner's four diagonal neighbourhoods are sampled: this share of the way to the next
// corner along each grid direction, both ways. Far enough from the corner to clear its blur, near
// enough that, at the grid's edge, stepping back along the last step instead of forward (the
// only step there is) still lands in the right square under perspective and distortion.
constexpr float kQuadrantReach = 0.3f;
// At a chessboard corner the two diagonal pairs differ by about twice the corner's contrast
// (|(a + c) - (b + d)| = 2 (light - dark)); where the board's outline meets a square (three
// neighbourhoods alike) by about once. Measured on the opencv-doc photographs: 1.9 to 2.0 at real
// corners, 0.0 to 1.3 at corners a grown grid put on the outline.
constexpr float kMinimumCornerScore = 1.5f;
// A cell is one square when the brightness at its centre and halfway to its four corners spreads
// by less than this share of the board's contrast; a cell spanning two or more squares has a
// square of each colour among those five points.
constexpr float kMaximumCellSpread = 0.5f;
// Below this contrast (8-bit levels) a neighbourhood is not a chessboard's at all.
constexpr float kMinimumContrast = 8;
// Share of corners, and of cells, that may fail (glare on a print, a speck of dust) in a grid
// that is still taken as labelled right; a grid that skips corners fails a whole row or column.
constexpr double kToleratedFailures = 0.05;

// Corner (column i, row j) of a grid `w` columns wide, listed row by row.
std::size_t index(int j, int w, int i) {
  return static_cast<std::size_t>(j) * static_cast<std::size_t>(w) + static_cast<std::size_t>(i);
}

// Brightness of `smooth` (CV_32F) at each point, bilinear.
std::vector<float> sampleAt(const cv::Mat& smooth, const std::vector<cv::Point2f>& points) {
  cv::Mat map(1, static_cast<int>(points.size()), CV_32FC2);
  std::copy(points.begin(), points.end(), map.begin<cv::Point2f>());
  cv::Mat values;
  cv::remap(smooth, values, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
  return {values.begin<float>(), values.end<float>()};
}

struct GridScores {
  std::vector<char> goodCorners;  // row by row, as the grid
  int badCorners = 0;
  int badCells = 0;
  int cells = 0;
};

GridScores scoreGrid(const cv::Mat& smooth, const ChessboardGrid& grid) {
  const int w = grid.size.width, h = grid.size.height;
  const auto at = [&](int i, int j) { return grid.corners[index(j, w, i)]; };
  // Each corner's four diagonal neighbourhoods, the steps to its neighbours taken forward and
  // back (at the grid's edge, the one step there is, both ways).
  std::vector<cv::Point2f> points;
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      const cv::Point2f p = at(i, j);
      const cv::Point2f right = i + 1 < w ? at(i + 1, j) - p : p - at(i - 1, j);
      const cv::Point2f left = i > 0 ? at(i - 1, j) - p : -right;
      const cv::Point2f down = j + 1 < h ? at(i, j + 1) - p : p - at(i, j - 1);
      const cv::Point2f up = j > 0 ? at(i, j - 1) - p : -down;
      for (const auto& corner : {right + down, left + down, left + up, right + up}) {
        points.push_back(p + kQuadrantReach * corner);
      }
    }
  }
  const std::size_t cornerSamples = points.size();
  for (int j = 0; j + 1 < h; ++j) {
    for (int i = 0; i + 1 < w; ++i) {
      const std::array<cv::Point2f, 4> cell{at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)};
      const cv::Point2f centre = (cell[0] + cell[1] + cell[2] + cell[3]) * 0.25f;
      points.push_back(centre);
      for (const auto& corner : cell) points.push_back((centre + corner) * 0.5f);
    }
  }
  const auto values = sampleAt(smooth, points);

  GridScores scores;
  std::vector<float> contrasts;
  for (std::size_t k = 0; k < cornerSamples; k += 4) {
    const auto q = values.begin() + static_cast<std::ptrdiff_t>(k);
    const auto [dark, light] = std::minmax_element(q, q + 4);
    const float contrast = *light - *dark;
    const float alternation = std::abs(q[0] + q[2] - q[1] - q[3]);
    const bool good = contrast >= kMinimumContrast && alternation >= kMinimumCornerScore * contrast;
    scores.goodCorners.push_back(good ? 1 : 0);
    if (good) contrasts.push_back(contrast);
  }
  scores.badCorners =
      static_cast<int>(std::count(scores.goodCorners.begin(), scores.goodCorners.end(), 0));
  if (contrasts.empty()) return scores;
  const auto middle = contrasts.begin() + static_cast<std::ptrdiff_t>(contrasts.size() / 2);
  std::nth_element(contrasts.begin(), middle, contrasts.end());
  const float boardContrast = *middle;
  for (std::size_t k = cornerSamples; k < values.size(); k += 5) {
    const auto q = values.begin() + static_cast<std::ptrdiff_t>(k);
    const auto [dark, light] = std::minmax_element(q, q + 5);
    ++scores.cells;
    if (*light - *dark > kMaximumCellSpread * boardContrast) ++scores.badCells;
  }
  return scores;
}

// The grid less one outer row or column: 0 top, 1 bottom, 2 left, 3 right.
ChessboardGrid withoutSide(const ChessboardGrid& grid, int side) {
  ChessboardGrid smaller;
  const int w = grid.size.width, h = grid.size.height;
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      if ((side == 0 && j == 0) || (side == 1 && j == h - 1) || (side == 2 && i == 0) ||
          (side == 3 && i == w - 1)) {
        continue;
      }
      smaller.corners.push_back(grid.corners[index(j, w, i)]);
    }
  }
  smaller.size = side < 2 ? cv::Size(w, h - 1) : cv::Size(w - 1, h);
  return smaller;
}

// Of the four outer rows and columns, the one with the largest share of failed corners, if more
// than half of its corners failed; -1 when none.
int worstSide(const ChessboardGrid& grid, const std::vector<char>& goodCorners) {
  const int w = grid.size.width, h = grid.size.height;
  std::array<double, 4> failed{};
  for (int j = 0; j < h; ++j) {
    for (int i = 0; i < w; ++i) {
      if (goodCorners[index(j, w, i)]) continue;
      if (j == 0) failed[0] += 1.0 / w;
      if (j == h - 1) failed[1] += 1.0 / w;
      if (i == 0) failed[2] += 1.0 / h;
      if (i == w - 1) failed[3] += 1.0 / h;
    }
  }
  const auto worst = std::max_element(failed.begin(), failed.end());
  return *worst > 0.5 ? static_cast<int>(worst - failed.begin()) : -1;
}

}  // namespace

std::optional<ChessboardGrid> checkedChessboardGrid(const cv::Mat& gray, ChessboardGrid grid) {
  if (grid.size.area() != static_cast<int>(grid.corners.size())) return std::nullopt;
  // Single samples of a noisy picture: smoothed a little first.
  cv::Mat smooth;
  gray.convertTo(smooth, CV_32F);
  cv::GaussianBlur(smooth, smooth, {0, 0}, 1.0);
  while (grid.size.width >= 2 && grid.size.height >= 2) {
    const GridScores scores = scoreGrid(smooth, grid);
    if (const int side = worstSide(grid, scores.goodCorners); side >= 0) {
      grid = withoutSide(grid, side);
      continue;
    }
    const bool labelledRight = scores.badCorners <= kToleratedFailures * grid.size.area() &&
                               scores.cells > 0 &&
                               scores.badCells <= kToleratedFailures * scores.cells;
    if (!labelledRight) return std::nullopt;
    return grid;
  }
  return std::nullopt;
}

}  // namespace surroundd::processing
