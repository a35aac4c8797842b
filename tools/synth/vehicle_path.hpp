#pragma once
// Where the vehicle is at time t: a slow drive along a gentle left curve (constant speed and yaw
// rate, so the pose has a closed form and any frame can be rendered on its own).
//
// World frame: ground plane z = 0, origin where the vehicle starts, x its initial heading, y left.
// The vehicle frame (DESIGN.md §4) is the world frame moved by this pose; the ground stays flat, so
// the pose is a yaw and a translation in the plane.

#include <cmath>

#include <opencv2/core.hpp>

namespace surroundd::synth {

struct VehiclePose {
  double x = 0;    // metres, world
  double y = 0;    // metres, world
  double yaw = 0;  // radians, heading of vehicle +x in the world, positive turns left

  cv::Vec3d toWorld(const cv::Vec3d& pointVehicle) const {
    const double c = std::cos(yaw);
    const double s = std::sin(yaw);
    return {x + c * pointVehicle[0] - s * pointVehicle[1],
            y + s * pointVehicle[0] + c * pointVehicle[1], pointVehicle[2]};
  }
  cv::Vec3d toVehicle(const cv::Vec3d& pointWorld) const {
    const double c = std::cos(yaw);
    const double s = std::sin(yaw);
    const double dx = pointWorld[0] - x;
    const double dy = pointWorld[1] - y;
    return {c * dx + s * dy, -s * dx + c * dy, pointWorld[2]};
  }
  // Directions turn with the vehicle but do not move with it.
  cv::Vec3d directionToWorld(const cv::Vec3d& d) const {
    const double c = std::cos(yaw);
    const double s = std::sin(yaw);
    return {c * d[0] - s * d[1], s * d[0] + c * d[1], d[2]};
  }
};

class VehiclePath {
 public:
  static constexpr double kSpeedMps = 1.5;         // walking pace: motion stays sub-pixel per frame
  static constexpr double kYawRateRadPerS = 0.04;  // turning radius 37.5 m

  static VehiclePose poseAt(double seconds) {
    const double yaw = kYawRateRadPerS * seconds;
    const double radius = kSpeedMps / kYawRateRadPerS;
    return {radius * std::sin(yaw), radius * (1 - std::cos(yaw)), yaw};
  }
};

}  // namespace surroundd::synth
