#include "processing/calibration/mat_board_detection.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <variant>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "processing/calibration/target_detection.hpp"
#include "processing/lens/camera_model.hpp"

namespace surroundd::processing {
namespace {

constexpr double kRadToDeg = 180 / std::numbers::pi;

// A top view of the ground around one board, in the board's pattern frame: top-view pixel (x, y)
// shows pattern point origin + (x, y) * metresPerPx, so the print appears upright and unmirrored.
struct TopView {
  cv::Mat image;
  cv::Point2d origin;
  double metresPerPx = 0;

  cv::Point2d toPattern(cv::Point2f px) const { return origin + cv::Point2d(px) * metresPerPx; }
  cv::Point2f toPixel(cv::Point2d pattern) const {
    return cv::Point2f((pattern - origin) * (1 / metresPerPx));
  }
};

// Where a pattern point of `print` lands in the picture under the nominal pose.
std::optional<cv::Point2d> pictureOf(const GroundMarker& print, cv::Point2d pattern,
                                     const CameraModel& model, const Pose& nominal) {
  const auto pixel = model.project(nominal.toCamera(print.toVehicle(pattern)));
  if (!pixel || !model.inImage(*pixel)) return std::nullopt;
  return pixel;
}

TopView topViewAround(const cv::Mat& gray, const GroundMarker& print, const CameraModel& model,
                      const Pose& nominal, const MatDetectionSettings& settings) {
  const double square = print.board.squareM;
  const cv::Size inner = print.board.innerCorners;
  // The print with its outer squares, and the search margin around it.
  const double reach = 2 * square + settings.searchMarginM;
  const cv::Point2d low(-reach, -reach);
  const cv::Point2d high((inner.width - 1) * square + reach, (inner.height - 1) * square + reach);
  TopView view;
  view.origin = low;
  view.metresPerPx = std::max(square / settings.topViewPxPerSquare,
                              std::max(high.x - low.x, high.y - low.y) / settings.topViewMaxSidePx);
  const cv::Size size(static_cast<int>(std::ceil((high.x - low.x) / view.metresPerPx)) + 1,
                      static_cast<int>(std::ceil((high.y - low.y) / view.metresPerPx)) + 1);
  cv::Mat map(size, CV_32FC2, cv::Scalar(-100, -100));  // off the picture: the border value
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const auto pixel = pictureOf(
          print, view.toPattern(cv::Point2f(static_cast<float>(x), static_cast<float>(y))), model,
          nominal);
      if (pixel) map.at<cv::Vec2f>(y, x) = cv::Vec2f(cv::Point2f(*pixel));
    }
  }
  cv::remap(gray, view.image, map, cv::noArray(), cv::INTER_LINEAR, cv::BORDER_CONSTANT,
            cv::mean(gray));
  return view;
}

// The grid's listing turned a quarter (square grids) or half turn: the same corners, numbered from
// another corner of the board.
std::vector<cv::Point2f> turned(const std::vector<cv::Point2f>& corners, cv::Size inner,
                                int quarters) {
  std::vector<cv::Point2f> result = corners;
  if (quarters == 2) {
    std::reverse(result.begin(), result.end());
    return result;
  }
  const auto n = static_cast<std::size_t>(inner.width);  // square
  for (int q = 0; q < quarters; ++q) {
    std::vector<cv::Point2f> next(result.size());
    for (std::size_t j = 0; j < n; ++j) {
      for (std::size_t i = 0; i < n; ++i) next[j * n + i] = result[i * n + n - 1 - j];
    }
    result = std::move(next);
  }
  return result;
}

struct Oriented {
  std::vector<cv::Point2f> corners;  // top-view pixels, in the board's order
  bool byNominalPose = false;
};

// Of the listings the board's symmetry allows and its colours do not rule out, the one whose
// corners lie nearest the layout's (ground_mat.hpp, mat_board_detection.hpp).
Oriented orient(const std::vector<cv::Point2f>& found, const TopView& view,
                const Checkerboard& board) {
  const cv::Size inner = board.innerCorners;
  const std::vector<int> turns =
      inner.width == inner.height ? std::vector<int>{0, 1, 2, 3} : std::vector<int>{0, 2};
  const auto pattern = board.patternCorners();
  Oriented best;
  double bestDistance = std::numeric_limits<double>::max();
  int candidates = 0;
  for (const int quarters : turns) {
    auto corners = turned(found, inner, quarters);
    if (blackFirstScore(view.image, corners, inner) <= 0) continue;
    ++candidates;
    double distance = 0;
    for (std::size_t k = 0; k < corners.size(); ++k) {
      distance += cv::norm(view.toPattern(corners[k]) - cv::Point2d(pattern[k].x, pattern[k].y));
    }
    if (distance < bestDistance) {
      bestDistance = distance;
      best.corners = std::move(corners);
    }
  }
  best.byNominalPose = candidates > 1;
  return best;
}

std::variant<MatBoardSighting, std::string> findBoard(const cv::Mat& gray, const MatBoard& board,
                                                      const CameraModel& model, const Pose& nominal,
                                                      const MatDetectionSettings& settings) {
  const GroundMarker& print = board.print;
  const cv::Size inner = print.board.innerCorners;
  if (!pictureOf(print,
                 {(inner.width - 1) * print.board.squareM / 2,
                  (inner.height - 1) * print.board.squareM / 2},
                 model, nominal)) {
    return std::string("the camera's nominal mount does not see its place in the layout");
  }
  const TopView view = topViewAround(gray, print, model, nominal, settings);
  const auto found = findCheckerboard(view.image, inner);
  if (!found) {
    return fmt::format("no {}x{} board within {:.2g} m of its place in the layout", inner.width,
                       inner.height, settings.searchMarginM);
  }
  const Oriented oriented = orient(*found, view, print.board);
  if (oriented.corners.empty()) {
    return std::string(
        "its squares' colours fit no orientation of the board; is it a board of "
        "this size?");
  }
  const auto& c = oriented.corners;
  const cv::Point2d along =
      view.toPattern(c[static_cast<std::size_t>(inner.width - 1)]) - view.toPattern(c[0]);
  const double turnDeg = std::abs(std::atan2(along.y, along.x)) * kRadToDeg;
  if (turnDeg > 45) {
    return fmt::format(
        "found turned {:.0f} degrees from its yaw_deg in the layout; is the yaw "
        "right, or the camera's mount that far off?",
        turnDeg);
  }
  MatBoardSighting sighting;
  sighting.orientedByNominalPose = oriented.byNominalPose;
  for (const auto& corner : c) {
    const auto pixel = pictureOf(print, view.toPattern(corner), model, nominal);
    if (!pixel) return std::string("part of it lies outside the picture");
    sighting.pixels.emplace_back(*pixel);
  }
  return sighting;
}

}  // namespace

MatBoardDetection findMatBoards(const cv::Mat& gray, const MatLayout& layout,
                                const CameraCalibration& nominal,
                                const MatDetectionSettings& settings) {
  const CameraModel model(nominal.intrinsics);
  MatBoardDetection detection;
  for (const std::size_t b : boardsSeenBy(layout, nominal.name)) {
    auto result = findBoard(gray, layout.boards[b], model, nominal.pose, settings);
    if (auto* sighting = std::get_if<MatBoardSighting>(&result)) {
      sighting->board = b;
      detection.found.push_back(std::move(*sighting));
    } else {
      detection.missed.push_back({b, std::get<std::string>(std::move(result))});
    }
  }
  return detection;
}

}  // namespace surroundd::processing
