#include "tools/synth/target_renderer.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/aruco/charuco.hpp>
#include <opencv2/aruco/dictionary.hpp>

namespace surroundd::synth {
namespace {

// Reflectances of the print, the floor and the wall, and the sky's brightness on the same scale:
// a print's black is not black and its white not the brightest thing in view, as on a real floor.
constexpr float kBlack = 0.06f;
constexpr float kWhite = 0.82f;
constexpr float kFloor = 0.32f;
constexpr float kWall = 0.45f;
constexpr float kSky = 0.9f;

constexpr float kNotALens = std::numeric_limits<float>::quiet_NaN();

int floorToInt(double x) { return static_cast<int>(std::floor(x)); }

}  // namespace

TargetPattern TargetPattern::checkerboard(const processing::Checkerboard& board) {
  // Squares (a, b), a = 0..W, b = 0..H, square (0, 0) black; then a white margin of one square.
  TargetPattern pattern;
  const cv::Size squares(board.innerCorners.width + 1, board.innerCorners.height + 1);
  pattern.modules_.create(squares.height + 2, squares.width + 2, CV_8U);
  pattern.modules_.setTo(1);
  for (int b = 0; b < squares.height; ++b) {
    for (int a = 0; a < squares.width; ++a) {
      pattern.modules_.at<std::uint8_t>(b + 1, a + 1) = (a + b) % 2 == 0 ? 0 : 1;
    }
  }
  pattern.moduleM_ = board.squareM;
  pattern.moduleOrigin_ = {-2 * board.squareM, -2 * board.squareM};
  return pattern;
}

TargetPattern TargetPattern::aruco(int dictionary, int id, double sideM) {
  // The marker with its one-module black border, then a white quiet zone of one module.
  const auto dict = cv::aruco::getPredefinedDictionary(dictionary);
  const int side = dict->markerSize + 2;
  cv::Mat marker;
  dict->drawMarker(id, side, marker, 1);
  TargetPattern pattern;
  pattern.modules_.create(side + 2, side + 2, CV_8U);
  pattern.modules_.setTo(1);
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      pattern.modules_.at<std::uint8_t>(y + 1, x + 1) = marker.at<std::uint8_t>(y, x) > 127 ? 1 : 0;
    }
  }
  pattern.moduleM_ = sideM / side;
  pattern.moduleOrigin_ = {-pattern.moduleM_, -pattern.moduleM_};
  return pattern;
}

std::optional<float> TargetPattern::albedo(double u, double v) const {
  const int i = floorToInt((u - moduleOrigin_.x) / moduleM_);
  const int j = floorToInt((v - moduleOrigin_.y) / moduleM_);
  if (i < 0 || j < 0 || i >= modules_.cols || j >= modules_.rows) return std::nullopt;
  return modules_.at<std::uint8_t>(j, i) != 0 ? kWhite : kBlack;
}

PlacedTarget placeGroundMarker(const processing::GroundMarker& marker, int arucoDictionary) {
  return {marker.kind == processing::MarkerKind::kAruco
              ? TargetPattern::aruco(arucoDictionary, marker.arucoId, marker.arucoSideM)
              : TargetPattern::checkerboard(marker.board),
          marker.origin(), marker.uAxis(), marker.vAxis()};
}

PlacedTarget placeBoard(const processing::Checkerboard& board,
                        const processing::Pose& boardInCamera) {
  return placePattern(TargetPattern::checkerboard(board), boardInCamera);
}

PlacedTarget placePattern(TargetPattern pattern, const processing::Pose& patternInCamera) {
  const cv::Matx33d& r = patternInCamera.rotation;
  return {std::move(pattern),
          patternInCamera.position,
          {r(0, 0), r(1, 0), r(2, 0)},
          {r(0, 1), r(1, 1), r(2, 1)}};
}

TargetPattern TargetPattern::charuco(cv::Size squares, int dictionary, double markerToSquare,
                                     double squareM) {
  // Drawn at this many modules a square: the markers' cells land on whole modules for the
  // usual ratios, and the square edges exactly on module edges.
  constexpr int kModulesPerSquare = 40;
  const auto board = cv::aruco::CharucoBoard::create(
      squares.width, squares.height, 1.0f, static_cast<float>(markerToSquare),
      cv::aruco::getPredefinedDictionary(dictionary));
  cv::Mat drawn;
  board->draw({squares.width * kModulesPerSquare, squares.height * kModulesPerSquare}, drawn, 0, 1);
  TargetPattern pattern;
  pattern.modules_.create(drawn.rows + 2 * kModulesPerSquare, drawn.cols + 2 * kModulesPerSquare,
                          CV_8U);
  pattern.modules_.setTo(1);
  cv::Mat inside =
      pattern.modules_(cv::Rect(kModulesPerSquare, kModulesPerSquare, drawn.cols, drawn.rows));
  inside.setTo(0);
  inside.setTo(1, drawn > 127);
  pattern.moduleM_ = squareM / kModulesPerSquare;
  pattern.moduleOrigin_ = {-squareM, -squareM};
  return pattern;
}

TargetRenderer::TargetRenderer(const processing::Intrinsics& intrinsics, int supersampling)
    : size_(intrinsics.imageSize),
      samples_(supersampling),
      fisheye_(processing::isWideAngle(intrinsics.model)),
      rays_(static_cast<std::size_t>(size_.area() * supersampling * supersampling)),
      offAxisAngle_(size_, CV_32F) {
  const processing::CameraModel model(intrinsics);
  const int perPixel = samples_ * samples_;
  cv::parallel_for_(cv::Range(0, size_.height), [&](const cv::Range& rows) {
    for (int y = rows.start; y < rows.end; ++y) {
      for (int x = 0; x < size_.width; ++x) {
        const auto centre = model.unproject({static_cast<double>(x), static_cast<double>(y)});
        offAxisAngle_.at<float>(y, x) =
            centre ? static_cast<float>(std::acos(std::clamp((*centre)[2], -1.0, 1.0))) : -1.0f;
        cv::Vec3f* samples =
            rays_.data() + static_cast<std::ptrdiff_t>(y * size_.width + x) * perPixel;
        for (int k = 0; k < perPixel; ++k) {
          // Stratified: sample centres on a regular grid inside the pixel [x - 0.5, x + 0.5).
          const int column = k % samples_, row = k / samples_;
          const double sx = x - 0.5 + (column + 0.5) / samples_;
          const double sy = y - 0.5 + (row + 0.5) / samples_;
          const auto ray = centre ? model.unproject({sx, sy}) : std::nullopt;
          samples[k] = ray ? cv::Vec3f(*ray) : cv::Vec3f(kNotALens, kNotALens, kNotALens);
        }
      }
    }
  });
}

cv::Mat TargetRenderer::render(const processing::Pose& cameraPose, const TargetScene& scene,
                               const CameraPhotometrics& photometrics, std::uint64_t seed,
                               int frameIndex) const {
  const PhotometricCamera sensor(photometrics, seed, 0, offAxisAngle_, fisheye_);
  const PhotometricCamera::Frame frame = sensor.frame(frameIndex, 0.0);
  const cv::Vec3d position = cameraPose.position;
  const cv::Matx33d rotation = cameraPose.rotation;
  const int perPixel = samples_ * samples_;

  // Radiance (0..255) of one ray, scene frame.
  const auto shade = [&](const cv::Vec3d& d) -> float {
    double nearest = std::numeric_limits<double>::infinity();
    float albedo = scene.floor ? (d[2] < 0 ? kFloor : kSky) : kWall;
    for (const PlacedTarget& target : scene.targets) {
      const cv::Vec3d normal = target.uAxis.cross(target.vAxis);
      const double facing = normal.dot(d);
      if (std::abs(facing) < 1e-12) continue;
      const double t = normal.dot(target.origin - position) / facing;
      if (t <= 0 || t >= nearest) continue;
      const cv::Vec3d onPlane = position + t * d - target.origin;
      if (const auto a =
              target.pattern.albedo(onPlane.dot(target.uAxis), onPlane.dot(target.vAxis))) {
        nearest = t;
        albedo = *a;
      }
    }
    // A floor in front of every target would hide it; targets lie on the floor or above it.
    if (scene.floor && d[2] < 0 && position[2] > 0 && -position[2] / d[2] < nearest * (1 - 1e-9)) {
      albedo = kFloor;
    }
    return albedo * 255.0f;
  };

  cv::Mat image(size_, CV_8UC3);
  cv::parallel_for_(cv::Range(0, size_.height), [&](const cv::Range& rows) {
    std::vector<cv::Vec3f> radiance(static_cast<std::size_t>(size_.width));
    for (int y = rows.start; y < rows.end; ++y) {
      for (int x = 0; x < size_.width; ++x) {
        const cv::Vec3f* samples =
            rays_.data() + static_cast<std::ptrdiff_t>(y * size_.width + x) * perPixel;
        float sum = 0;
        int count = 0;
        for (int k = 0; k < perPixel; ++k) {
          if (std::isnan(samples[k][0])) continue;
          sum += shade(rotation * cv::Vec3d(samples[k]));
          ++count;
        }
        const float value = count > 0 ? sum / static_cast<float>(count) : 0.0f;
        radiance[static_cast<std::size_t>(x)] = cv::Vec3f(value, value, value);
      }
      sensor.convertRow(frame, radiance.data(), image.ptr<cv::Vec3b>(y), y, 0, size_.width);
    }
  });
  return image;
}

}  // namespace surroundd::synth
