#include "tools/calibrate/import/canvas_strips.hpp"

#include <algorithm>
#include <array>

namespace surroundd::calibrate {

std::optional<VehicleSide> sideInName(std::string_view camera) {
  static constexpr std::array<std::string_view, 4> kNames{"front", "back", "left", "right"};
  const auto name = std::ranges::find_if(
      kNames, [&](std::string_view side) { return camera.find(side) != std::string_view::npos; });
  if (name == kNames.end()) return std::nullopt;
  const std::array<cv::Vec2d, 4> directions{{{1, 0}, {-1, 0}, {0, 1}, {0, -1}}};
  return VehicleSide{*name, directions[static_cast<std::size_t>(name - kNames.begin())]};
}

cv::Matx33d stripFromCanvas(const VehicleSide& side, cv::Size canvasSize) {
  // A turn takes pixel index i of a side of n pixels to n - 1 - i.
  const double lastColumn = canvasSize.width - 1.0, lastRow = canvasSize.height - 1.0;
  if (side.name == "back") return {-1, 0, lastColumn, 0, -1, lastRow, 0, 0, 1};
  if (side.name == "left") return {0, -1, lastRow, 1, 0, 0, 0, 0, 1};
  if (side.name == "right") return {0, 1, 0, -1, 0, lastColumn, 0, 0, 1};
  return cv::Matx33d::eye();
}

}  // namespace surroundd::calibrate
