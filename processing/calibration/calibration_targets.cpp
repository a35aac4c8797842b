#include "processing/calibration/calibration_targets.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <utility>

#include <opencv2/aruco/dictionary.hpp>

namespace surroundd::processing {
namespace {

constexpr std::array<std::pair<std::string_view, int>, 12> kArucoDictionaries{{
    {"4x4_50", cv::aruco::DICT_4X4_50},
    {"4x4_100", cv::aruco::DICT_4X4_100},
    {"4x4_250", cv::aruco::DICT_4X4_250},
    {"5x5_50", cv::aruco::DICT_5X5_50},
    {"5x5_100", cv::aruco::DICT_5X5_100},
    {"5x5_250", cv::aruco::DICT_5X5_250},
    {"6x6_50", cv::aruco::DICT_6X6_50},
    {"6x6_100", cv::aruco::DICT_6X6_100},
    {"6x6_250", cv::aruco::DICT_6X6_250},
    {"aruco_original", cv::aruco::DICT_ARUCO_ORIGINAL},
    {"apriltag_25h9", cv::aruco::DICT_APRILTAG_25h9},
    {"apriltag_36h11", cv::aruco::DICT_APRILTAG_36h11},
}};

}  // namespace

std::vector<cv::Point3f> Checkerboard::patternCorners() const {
  std::vector<cv::Point3f> corners;
  corners.reserve(static_cast<std::size_t>(innerCorners.area()));
  for (int j = 0; j < innerCorners.height; ++j) {
    for (int i = 0; i < innerCorners.width; ++i) {
      corners.emplace_back(static_cast<float>(i * squareM), static_cast<float>(j * squareM), 0.0f);
    }
  }
  return corners;
}

cv::Vec3d GroundMarker::uAxis() const {
  const double yaw = yawDeg * std::numbers::pi / 180;
  return {std::cos(yaw), std::sin(yaw), 0};
}

cv::Vec3d GroundMarker::vAxis() const { return uAxis().cross(cv::Vec3d(0, 0, 1)); }

cv::Vec3d GroundMarker::origin() const {
  const cv::Point2d half = kind == MarkerKind::kAruco
                               ? cv::Point2d(arucoSideM / 2, arucoSideM / 2)
                               : cv::Point2d((board.innerCorners.width - 1) * board.squareM / 2,
                                             (board.innerCorners.height - 1) * board.squareM / 2);
  return centre - half.x * uAxis() - half.y * vAxis();
}

std::vector<cv::Point3d> GroundMarker::corners() const {
  std::vector<cv::Point3d> out;
  if (kind == MarkerKind::kAruco) {
    for (const auto& [u, v] : {std::pair{0, 0}, {1, 0}, {1, 1}, {0, 1}}) {
      out.emplace_back(toVehicle({u * arucoSideM, v * arucoSideM}));
    }
    return out;
  }
  for (const auto& corner : board.patternCorners())
    out.emplace_back(toVehicle({corner.x, corner.y}));
  return out;
}

std::optional<int> arucoDictionaryByName(std::string_view name) {
  for (const auto& [known, id] : kArucoDictionaries) {
    if (known == name) return id;
  }
  return std::nullopt;
}

std::string_view arucoDictionaryName(int dictionary) {
  for (const auto& [known, id] : kArucoDictionaries) {
    if (id == dictionary) return known;
  }
  return "?";
}

std::string arucoDictionaryNames() {
  std::string names;
  for (const auto& [known, id] : kArucoDictionaries) {
    if (!names.empty()) names += ", ";
    names += known;
  }
  return names;
}

}  // namespace surroundd::processing
