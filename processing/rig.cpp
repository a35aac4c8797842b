#include "processing/rig.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

namespace surroundd::processing {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

using RowMajor3d = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;

// Camera looking along vehicle +x with its image upright: camera x = -y, y = -z, z = +x (vehicle).
cv::Matx33d baseRotation() { return {0, 0, 1, -1, 0, 0, 0, -1, 0}; }

// cv::Matx stores its values row by row.
cv::Matx33d toMatx(const Eigen::Matrix3d& m) {
  cv::Matx33d out;
  Eigen::Map<RowMajor3d>(out.val) = m;
  return out;
}

}  // namespace

cv::Matx33d rotationFromMountAngles(const MountAngles& angles) {
  const Eigen::Quaterniond turn =
      Eigen::AngleAxisd(angles.yawDeg * kDegToRad, Eigen::Vector3d::UnitZ()) *
      Eigen::AngleAxisd(-angles.pitchDeg * kDegToRad, Eigen::Vector3d::UnitY()) *
      Eigen::AngleAxisd(angles.rollDeg * kDegToRad, Eigen::Vector3d::UnitX());
  return toMatx(turn.toRotationMatrix()) * baseRotation();
}

MountAngles mountAnglesFromRotation(const cv::Matx33d& rotation) {
  // rotation * base^T = Rz(yaw) * Ry(-pitch) * Rx(roll): read the Z-Y-X Euler angles. By hand,
  // not Eigen's eulerAngles(2, 1, 0): that one keeps the first angle in [0, 180] degrees, so a
  // camera mounted at yaw -90, pitch -40, roll 3 reads back as yaw 90, pitch -140, roll -177 —
  // the same rotation, not the mount's angles (pitch here stays in [-90, 90]).
  const cv::Matx33d m = rotation * baseRotation().t();
  return {std::atan2(m(1, 0), m(0, 0)) / kDegToRad,
          std::asin(std::clamp(m(2, 0), -1.0, 1.0)) / kDegToRad,
          std::atan2(m(2, 1), m(2, 2)) / kDegToRad};
}

cv::Matx33d rotationFromQuaternion(const cv::Vec4d& wxyz) {
  return toMatx(Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]).toRotationMatrix());
}

}  // namespace surroundd::processing
