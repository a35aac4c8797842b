#include "processing/rig.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace surroundd::processing {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

// Camera looking along vehicle +x with its image upright: camera x = -y, y = -z, z = +x (vehicle).
cv::Matx33d baseRotation() { return {0, 0, 1, -1, 0, 0, 0, -1, 0}; }

}  // namespace

cv::Matx33d rotationFromMountAngles(const MountAngles& angles) {
  const double yaw = angles.yawDeg * kDegToRad;
  const double pitch = -angles.pitchDeg * kDegToRad;
  const double roll = angles.rollDeg * kDegToRad;
  const cv::Matx33d rz(std::cos(yaw), -std::sin(yaw), 0, std::sin(yaw), std::cos(yaw), 0, 0, 0, 1);
  const cv::Matx33d ry(std::cos(pitch), 0, std::sin(pitch), 0, 1, 0, -std::sin(pitch), 0,
                       std::cos(pitch));
  const cv::Matx33d rx(1, 0, 0, 0, std::cos(roll), -std::sin(roll), 0, std::sin(roll),
                       std::cos(roll));
  return rz * ry * rx * baseRotation();
}

MountAngles mountAnglesFromRotation(const cv::Matx33d& rotation) {
  // rotation * base^T = Rz(yaw) * Ry(-pitch) * Rx(roll): read the Z-Y-X Euler angles.
  const cv::Matx33d m = rotation * baseRotation().t();
  return {std::atan2(m(1, 0), m(0, 0)) / kDegToRad,
          std::asin(std::clamp(m(2, 0), -1.0, 1.0)) / kDegToRad,
          std::atan2(m(2, 1), m(2, 2)) / kDegToRad};
}

}  // namespace surroundd::processing
