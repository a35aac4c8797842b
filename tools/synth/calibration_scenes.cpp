#include "tools/synth/calibration_scenes.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

#include <fmt/format.h>
#include <opencv2/aruco/dictionary.hpp>
#include <opencv2/calib3d.hpp>

#include "processing/calibration/target_detection.hpp"
#include "processing/lens/camera_model.hpp"
#include "tools/synth/hash.hpp"

namespace surroundd::synth {
namespace {

constexpr std::uint64_t kBoardPoseStream = 41;
constexpr std::uint64_t kGroundMarkerStream = 42;
constexpr double kDegToRad = std::numbers::pi / 180;
constexpr double kEdgeMarginPx = 4;  // detectors need a little room around a target
constexpr int kAttempts = 400;

cv::Matx33d rotationAbout(const cv::Vec3d& axis, double angle) {
  cv::Matx33d rotation;
  cv::Rodrigues(cv::normalize(axis) * angle, rotation);
  return rotation;
}

// Pattern points a whole, unclipped view must show: the inner corners and the print's outline
// (its white margin's outer edge), densely enough that a fisheye's curved edges are covered too.
std::vector<cv::Point2d> outlineAndCorners(const std::vector<cv::Point2d>& corners,
                                           cv::Point2d topLeft, cv::Point2d bottomRight) {
  std::vector<cv::Point2d> points = corners;
  constexpr int kPerEdge = 8;
  for (int k = 0; k <= kPerEdge; ++k) {
    const double a = static_cast<double>(k) / kPerEdge;
    const double u = topLeft.x + a * (bottomRight.x - topLeft.x);
    const double v = topLeft.y + a * (bottomRight.y - topLeft.y);
    points.insert(points.end(),
                  {{u, topLeft.y}, {u, bottomRight.y}, {topLeft.x, v}, {bottomRight.x, v}});
  }
  return points;
}

std::vector<cv::Point2d> boardCheckPoints(const processing::Checkerboard& board) {
  std::vector<cv::Point2d> corners;
  for (const auto& c : board.patternCorners()) corners.emplace_back(c.x, c.y);
  const double s = board.squareM;
  return outlineAndCorners(
      corners, {-2 * s, -2 * s},
      {(board.innerCorners.width + 1) * s, (board.innerCorners.height + 1) * s});
}

// Pixels of camera-frame points, or nothing when one of them is off the image, too close to its
// edge, or further off the optical axis than `maxAngleRad`.
std::optional<std::vector<cv::Point2d>> pixelsIfSeen(const processing::CameraModel& model,
                                                     const std::vector<cv::Vec3d>& points,
                                                     double maxAngleRad) {
  const cv::Size size = model.intrinsics().imageSize;
  std::vector<cv::Point2d> pixels;
  for (const auto& p : points) {
    if (std::atan2(std::hypot(p[0], p[1]), p[2]) > maxAngleRad) return std::nullopt;
    const auto pixel = model.project(p);
    if (!pixel || pixel->x < kEdgeMarginPx || pixel->y < kEdgeMarginPx ||
        pixel->x > size.width - 1 - kEdgeMarginPx || pixel->y > size.height - 1 - kEdgeMarginPx) {
      return std::nullopt;
    }
    pixels.push_back(*pixel);
  }
  return pixels;
}

// ArUco side in modules: the code plus its one-module black border.
int arucoModules(int dictionary) {
  return cv::aruco::getPredefinedDictionary(dictionary)->markerSize + 2;
}

// Pattern points of a ground marker that must be in view: corners first, in detector order.
std::vector<cv::Point2d> markerCheckPoints(const processing::GroundMarker& marker, int modules) {
  if (marker.kind == processing::MarkerKind::kCheckerboard) return boardCheckPoints(marker.board);
  const double side = marker.arucoSideM;
  const double quiet = side / modules;
  return outlineAndCorners({{0, 0}, {side, 0}, {side, side}, {0, side}}, {-quiet, -quiet},
                           {side + quiet, side + quiet});
}

// Half the print's diagonal, white margin included: how close another marker may come.
double printRadius(const processing::GroundMarker& marker, int modules) {
  if (marker.kind == processing::MarkerKind::kAruco) {
    return marker.arucoSideM * (modules + 2) / modules / std::numbers::sqrt2;
  }
  const cv::Size inner = marker.board.innerCorners;
  return std::hypot(inner.width + 3, inner.height + 3) * marker.board.squareM / 2;
}

// The smallest square (board) or module (ArUco) in the image, pixels, from the corner pixels.
double smallestFeaturePx(const processing::GroundMarker& marker,
                         const std::vector<cv::Point2d>& pixels, int modules) {
  double smallest = std::numeric_limits<double>::max();
  if (marker.kind == processing::MarkerKind::kAruco) {
    for (std::size_t i = 0; i < 4; ++i) {
      smallest = std::min(smallest, cv::norm(pixels[(i + 1) % 4] - pixels[i]) / modules);
    }
    return smallest;
  }
  const std::vector<cv::Point2f> corners(pixels.begin(),
                                         pixels.begin() + marker.board.innerCorners.area());
  return processing::smallestGridStep(corners, marker.board.innerCorners);
}

// Whether the quadrilateral of the marker's outermost corners has every angle within 55..125
// degrees: a detector's corners on a strongly sheared print drift by pixels (cornerSubPix on the
// acute corners of a far ArUco marker: 1.6 px).
bool notTooSheared(const processing::GroundMarker& marker, const std::vector<cv::Point2d>& pixels) {
  std::array<cv::Point2d, 4> quad{pixels[0], pixels[1], pixels[2], pixels[3]};
  if (marker.kind == processing::MarkerKind::kCheckerboard) {
    const auto w = static_cast<std::size_t>(marker.board.innerCorners.width);
    const auto last = static_cast<std::size_t>(marker.board.innerCorners.area()) - 1;
    quad = {pixels[0], pixels[w - 1], pixels[last], pixels[last + 1 - w]};
  }
  const double limit = std::cos(55 * kDegToRad);
  for (std::size_t i = 0; i < 4; ++i) {
    const cv::Point2d a = quad[(i + 3) % 4] - quad[i], b = quad[(i + 1) % 4] - quad[i];
    if (std::abs(a.dot(b)) > limit * cv::norm(a) * cv::norm(b)) return false;
  }
  return true;
}

}  // namespace

std::vector<processing::Pose> boardPosesCoveringField(const processing::Intrinsics& intrinsics,
                                                      const processing::Checkerboard& board,
                                                      int count, std::uint64_t seed) {
  const processing::CameraModel model(intrinsics);
  const cv::Size size = intrinsics.imageSize;
  const bool fisheye = processing::isWideAngle(intrinsics.model);
  const double maxCornerAngle = (fisheye ? 80 : 89) * kDegToRad;
  const int cols = std::max(1, static_cast<int>(std::lround(std::sqrt(
                                   count * static_cast<double>(size.width) / size.height))));
  const int rows = (count + cols - 1) / cols;
  const cv::Vec3d patternCentre((board.innerCorners.width - 1) * board.squareM / 2,
                                (board.innerCorners.height - 1) * board.squareM / 2, 0);
  const double printWidthM = (board.innerCorners.width + 3) * board.squareM;
  const auto checkPoints = boardCheckPoints(board);

  std::vector<processing::Pose> poses;
  for (int k = 0; k < count; ++k) {
    HashRng rng(seed, kBoardPoseStream * 100000 + static_cast<std::uint64_t>(k));
    const int cellX = k % cols, cellY = k / cols;
    bool placed = false;
    for (int attempt = 0; attempt < kAttempts && !placed; ++attempt) {
      // Half the attempts in the view's own cell; then anywhere, rather than fail.
      const bool inCell = attempt < kAttempts / 2;
      // y before x: the order x86-64 builds drew them in (hash.hpp, HashRng).
      const double y =
          (inCell ? (cellY + rng.uniform(0.1, 0.9)) / rows : rng.uniform(0, 1)) * size.height;
      const double x =
          (inCell ? (cellX + rng.uniform(0.1, 0.9)) / cols : rng.uniform(0, 1)) * size.width;
      const cv::Point2d pixel(x, y);
      const auto ray = model.unproject(pixel);
      if (!ray || std::acos((*ray)[2]) > maxCornerAngle - 10 * kDegToRad) continue;
      // Facing the camera, upright, then rolled and tilted.
      const cv::Vec3d u0 = cv::normalize(cv::Vec3d(0, 1, 0).cross(*ray));
      const cv::Vec3d v0 = ray->cross(u0);
      const cv::Matx33d facing(u0[0], v0[0], (*ray)[0], u0[1], v0[1], (*ray)[1], u0[2], v0[2],
                               (*ray)[2]);
      const double roll = rng.uniform(-30, 30) * kDegToRad;
      const double tiltDirection = rng.uniform(0, 2 * std::numbers::pi);
      const double tilt = rng.uniform(15, 45) * kDegToRad;
      const cv::Vec3d tiltAxis = std::cos(tiltDirection) * u0 + std::sin(tiltDirection) * v0;
      const cv::Matx33d rotation =
          rotationAbout(tiltAxis, tilt) * rotationAbout(*ray, roll) * facing;
      const double fraction = rng.uniform(0.3, 0.55);  // of the image width
      const double distance = printWidthM * model.axisFocalPx()[0] / (fraction * size.width);
      const cv::Vec3d position = distance * *ray - rotation * patternCentre;
      std::vector<cv::Vec3d> points;
      points.reserve(checkPoints.size());
      for (const auto& p : checkPoints)
        points.push_back(rotation * cv::Vec3d(p.x, p.y, 0) + position);
      if (!pixelsIfSeen(model, points, maxCornerAngle)) continue;
      poses.push_back({rotation, position});
      placed = true;
    }
    if (!placed) {
      throw std::runtime_error(fmt::format(
          "no pose of a {}x{} board fits view {} of {} in a {}x{} image", board.innerCorners.width,
          board.innerCorners.height, k, count, size.width, size.height));
    }
  }
  return poses;
}

bool markerFitsView(const processing::CameraCalibration& camera,
                    const processing::GroundMarker& marker, int arucoDictionary,
                    const ViewFit& fit) {
  const processing::CameraModel model(camera.intrinsics);
  const int modules = arucoModules(arucoDictionary);
  std::vector<cv::Vec3d> points;
  for (const auto& p : markerCheckPoints(marker, modules)) {
    points.push_back(camera.pose.toCamera(marker.toVehicle(p)));
  }
  const auto pixels = pixelsIfSeen(model, points, std::numbers::pi);
  const bool isBoard = marker.kind == processing::MarkerKind::kCheckerboard;
  return pixels &&
         smallestFeaturePx(marker, *pixels, modules) >=
             (isBoard ? fit.minBoardSquarePx : fit.minArucoModulePx) &&
         (!fit.limitShear || notTooSheared(marker, *pixels));
}

processing::MarkerLayout groundMarkersInView(const processing::CameraCalibration& camera,
                                             const GroundMarkerRequest& request) {
  const processing::CameraModel model(camera.intrinsics);
  const cv::Size size = camera.intrinsics.imageSize;
  const processing::Pose& pose = camera.pose;
  HashRng rng(request.seed, kGroundMarkerStream);
  processing::MarkerLayout layout;
  layout.arucoDictionary = request.arucoDictionary;
  const int modules = arucoModules(request.arucoDictionary);
  const double minDirectionZ = std::sin(request.minElevationDeg * kDegToRad);

  const int wanted = request.boards + request.arucoMarkers;
  // Each marker first tries its own cell of a grid over the lower image, so that they spread.
  const int cols = std::max(1, static_cast<int>(std::ceil(std::sqrt(2.0 * wanted))));
  const int rows = (wanted + cols - 1) / cols;
  for (int n = 0; n < wanted; ++n) {
    processing::GroundMarker marker;
    const bool isBoard = n < request.boards;
    marker.kind = isBoard ? processing::MarkerKind::kCheckerboard : processing::MarkerKind::kAruco;
    marker.board = request.board;
    marker.arucoId = request.firstArucoId + n - request.boards;
    marker.arucoSideM = request.arucoSideM;
    marker.name = isBoard ? fmt::format("board{}", n) : fmt::format("aruco{}", marker.arucoId);
    const int cell = (n * 7) % (cols * rows);  // boards and markers interleaved over the cells
    for (int attempt = 0; attempt < kAttempts; ++attempt) {
      const bool inCell = attempt < kAttempts / 2;
      const int column = cell % cols, row = cell / cols;
      const double cellX = inCell ? (column + rng.uniform(0, 1)) / cols : rng.uniform(0, 1);
      const double cellY = inCell ? (row + rng.uniform(0, 1)) / rows : rng.uniform(0, 1);
      const auto ray =
          model.unproject({(0.05 + 0.9 * cellX) * size.width, (0.3 + 0.65 * cellY) * size.height});
      if (!ray) continue;
      const cv::Vec3d direction = pose.rotation * *ray;
      if (-direction[2] < minDirectionZ) continue;
      const cv::Vec3d ground = pose.position - pose.position[2] / direction[2] * direction;
      const double heading = std::atan2(ground[1] - pose.position[1], ground[0] - pose.position[0]);
      // u to the right of the line of sight, v towards the camera: the print upright in the view.
      marker.centre = {ground[0], ground[1], 0};
      marker.yawDeg = heading / kDegToRad - 90 + rng.uniform(-25, 25);
      const bool apart =
          std::all_of(layout.markers.begin(), layout.markers.end(), [&](auto& other) {
            return cv::norm(other.centre - marker.centre) >
                   printRadius(other, modules) + printRadius(marker, modules) + 0.1;
          });
      if (!apart) continue;
      if (!markerFitsView(camera, marker, request.arucoDictionary)) continue;
      layout.markers.push_back(marker);
      break;
    }
  }
  return layout;
}

}  // namespace surroundd::synth
