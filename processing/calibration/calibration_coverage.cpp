#include "processing/calibration/calibration_coverage.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "processing/calibration/intrinsic_calibration.hpp"
#include "processing/lens/camera_model.hpp"

namespace surroundd::processing {
namespace {

constexpr double kToDeg = 180 / std::numbers::pi;

// Dark: below the darkest level plus this share of the way to the median (and at least a few
// levels above it, for sensor noise).
constexpr double kDarkShare = 0.2;
constexpr double kMinimumDarkMargin = 6;

double percentile(const cv::Mat& gray, double share) {
  std::array<int, 256> histogram{};
  for (int y = 0; y < gray.rows; ++y) {
    const auto* row = gray.ptr<std::uint8_t>(y);
    for (int x = 0; x < gray.cols; ++x) ++histogram[row[x]];
  }
  const double wanted = share * static_cast<double>(gray.total());
  double seen = 0;
  for (int level = 0; level < 256; ++level) {
    seen += histogram[static_cast<std::size_t>(level)];
    if (seen >= wanted) return level;
  }
  return 255;
}

}  // namespace

ImageCircle findImageCircle(const cv::Mat& brightest) {
  cv::Mat smooth;
  cv::medianBlur(brightest, smooth, 5);  // single hot pixels are not the lens
  const double black = percentile(smooth, 0.001);
  const double median = percentile(smooth, 0.5);
  const double threshold = black + std::max(kMinimumDarkMargin, kDarkShare * (median - black));
  cv::Mat dark = smooth <= threshold;
  // Outside the circle is the dark that reaches the image border; dark inside it is scene.
  cv::Mat outside = cv::Mat::zeros(dark.rows + 2, dark.cols + 2, CV_8U);
  const int w = dark.cols, h = dark.rows;
  const auto seed = [&](int x, int y) {
    if (dark.at<std::uint8_t>(y, x) != 0 && outside.at<std::uint8_t>(y + 1, x + 1) == 0) {
      cv::floodFill(dark, outside, {x, y}, 0, nullptr, 0, 0,
                    4 | cv::FLOODFILL_MASK_ONLY | (255 << 8));
    }
  };
  for (int x = 0; x < w; ++x) seed(x, 0), seed(x, h - 1);
  for (int y = 0; y < h; ++y) seed(0, y), seed(w - 1, y);
  ImageCircle circle;
  const cv::Mat outsideInImage = outside(cv::Rect(1, 1, w, h));
  circle.lit = outsideInImage == 0;
  circle.seenInImage = outsideInImage.at<std::uint8_t>(0, 0) != 0 &&
                       outsideInImage.at<std::uint8_t>(0, w - 1) != 0 &&
                       outsideInImage.at<std::uint8_t>(h - 1, 0) != 0 &&
                       outsideInImage.at<std::uint8_t>(h - 1, w - 1) != 0;
  if (!circle.seenInImage) circle.lit.setTo(255);  // dark patches at the border are the scene
  return circle;
}

cv::Rect CoverageMap::cellRect(int column, int row) const {
  const int x0 = column * imageSize.width / cells.width;
  const int y0 = row * imageSize.height / cells.height;
  return {x0, y0, (column + 1) * imageSize.width / cells.width - x0,
          (row + 1) * imageSize.height / cells.height - y0};
}

std::vector<std::string> CoverageMap::uncoveredParts() const {
  // The image in thirds each way; a part is uncovered when none of its cells in the lens has a
  // corner.
  static constexpr std::array<std::array<const char*, 3>, 3> kNames{{
      {"the top left corner", "the top edge", "the top right corner"},
      {"the left edge", "the centre", "the right edge"},
      {"the bottom left corner", "the bottom edge", "the bottom right corner"},
  }};
  std::array<std::array<int, 3>, 3> counts{}, lensCells{};
  for (int row = 0; row < cells.height; ++row) {
    for (int column = 0; column < cells.width; ++column) {
      if (inLens.at<std::uint8_t>(row, column) == 0) continue;
      auto& count = counts[static_cast<std::size_t>(3 * row / cells.height)]
                          [static_cast<std::size_t>(3 * column / cells.width)];
      count += cornerCounts.at<int>(row, column);
      ++lensCells[static_cast<std::size_t>(3 * row / cells.height)]
                 [static_cast<std::size_t>(3 * column / cells.width)];
    }
  }
  std::vector<std::string> parts;
  for (std::size_t r = 0; r < 3; ++r) {
    for (std::size_t c = 0; c < 3; ++c) {
      if (lensCells[r][c] > 0 && counts[r][c] == 0) parts.emplace_back(kNames[r][c]);
    }
  }
  return parts;
}

CoverageMap coverageOf(std::span<const BoardView> views, cv::Size imageSize, const cv::Mat& lit,
                       int columns) {
  CoverageMap map;
  map.imageSize = imageSize;
  map.cells = {columns,
               std::max(1, static_cast<int>(std::lround(static_cast<double>(columns) *
                                                        imageSize.height / imageSize.width)))};
  map.cornerCounts = cv::Mat::zeros(map.cells.height, map.cells.width, CV_32S);
  map.inLens = cv::Mat::zeros(map.cells.height, map.cells.width, CV_8U);
  for (const auto& view : views) {
    for (const auto& corner : view.corners) {
      const double x = corner.x, y = corner.y;
      const int column =
          std::clamp(static_cast<int>(x * columns / imageSize.width), 0, map.cells.width - 1);
      const int row = std::clamp(static_cast<int>(y * map.cells.height / imageSize.height), 0,
                                 map.cells.height - 1);
      ++map.cornerCounts.at<int>(row, column);
    }
  }
  int inLens = 0, covered = 0;
  for (int row = 0; row < map.cells.height; ++row) {
    for (int column = 0; column < map.cells.width; ++column) {
      const cv::Rect cell = map.cellRect(column, row);
      const cv::Point centre(cell.x + cell.width / 2, cell.y + cell.height / 2);
      if (!lit.empty() && lit.at<std::uint8_t>(centre) == 0) continue;
      map.inLens.at<std::uint8_t>(row, column) = 1;
      ++inLens;
      if (map.cornerCounts.at<int>(row, column) > 0) ++covered;
    }
  }
  map.coveredShare = inLens > 0 ? static_cast<double>(covered) / inLens : 0;
  return map;
}

double widestCornerAngleRad(const Intrinsics& lens, std::span<const BoardView> views) {
  const CameraModel model(lens);
  double widest = 0;
  for (const auto& view : views) {
    for (const auto& corner : view.corners) {
      if (const auto ray = model.unproject({corner.x, corner.y})) {
        widest = std::max(widest, std::acos(std::clamp((*ray)[2] / cv::norm(*ray), -1.0, 1.0)));
      }
    }
  }
  return widest;
}

FieldOfView fieldOfViewOf(const Intrinsics& lens, const ImageCircle& circle,
                          std::optional<double> widestCornerRad) {
  FieldOfView field;
  const auto lit = widestLitFieldAngle(lens, circle.lit);
  double halfRad = lit.rad;
  field.fromImageCircle = circle.seenInImage && !lit.pastTheLens;
  if (const auto cut = CameraModel(lens).fieldCut();
      lit.pastTheLens || (cut && halfRad >= cut->atRad - 1e-6)) {
    field.note = fmt::format(
        "limited to {:.1f} deg: short of the picture's {}, the solved distortion stops "
        "increasing and gives no rays",
        2 * halfRad * kToDeg, circle.seenInImage ? "image circle" : "corners");
  }
  if (!circle.seenInImage && halfRad > std::numbers::pi / 2) {
    field.note = fmt::format(
        "the image circle is not in the pictures (their corners are lit): the corners would "
        "say {:.1f} deg, which nothing in the pictures confirms, so 180 deg is taken; give "
        "--field-of-view-deg for the lens's real field",
        2 * halfRad * kToDeg);
    halfRad = std::numbers::pi / 2;
  }
  if (const double reach = widestCornerRad.value_or(halfRad) + kFieldPastCornersDeg / kToDeg;
      widestCornerRad && halfRad > reach) {
    field.note = fmt::format(
        "limited to {:.1f} deg: the board's corners reached {:.1f} deg off the axis, and the "
        "solved distortion is taken {:g} deg past them, not to the {}'s {:.1f}; pictures with the "
        "board nearer the edge of the picture widen it, --field-of-view-deg sets it",
        2 * reach * kToDeg, *widestCornerRad * kToDeg, kFieldPastCornersDeg,
        field.fromImageCircle ? "image circle" : "picture", 2 * halfRad * kToDeg);
    field.fromImageCircle = false;
    halfRad = reach;
  }
  field.fullDeg = 2 * halfRad * kToDeg;
  return field;
}

}  // namespace surroundd::processing
