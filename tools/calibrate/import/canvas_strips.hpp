#pragma once
// Bird's-eye tools that give each camera a strip of the canvas of its own (surround-view-system-
// introduction's, for one): the camera's homography maps its picture to the strip, and the strip
// is turned onto the canvas with its top edge outward, along the canvas's edge on the camera's
// side: front as it is at the top, right turned 90 degrees clockwise at the right, back turned
// 180 degrees at the bottom, left turned 90 degrees counter-clockwise at the left. Each camera's
// side comes from its name.

#include <optional>
#include <string_view>

#include <opencv2/core.hpp>

namespace surroundd::calibrate {

struct VehicleSide {
  std::string_view name;  // front, back, left or right
  cv::Vec2d direction;    // vehicle frame: x forward, y left
};

// The first of front, back, left and right that the camera's name holds ("back_camera": back).
std::optional<VehicleSide> sideInName(std::string_view camera);

// From a pixel of the whole canvas (canvasSize, pixel centres at integer coordinates) to the pixel
// of the side's own strip.
cv::Matx33d stripFromCanvas(const VehicleSide& side, cv::Size canvasSize);

}  // namespace surroundd::calibrate
