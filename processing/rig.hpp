#pragma once
// The camera rig: what each camera is, where it sits on the vehicle, and its lens.
//
// Vehicle frame: origin on the ground under the vehicle centre, x forward, y left, z up, metres.
// A camera's pose is T_vehicle_camera: X_vehicle = rotation * X_camera + position.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/lens/camera_model.hpp"

namespace surroundd::processing {

// Role in Poisson colour correction: sources are corrected towards targets.
enum class ColourRole { kSource, kTarget };

struct Pose {
  cv::Matx33d rotation = cv::Matx33d::eye();  // columns: camera x, y, z axes in the vehicle frame
  cv::Vec3d position;                         // metres, vehicle frame

  cv::Vec3d toVehicle(const cv::Vec3d& pointCamera) const {
    return rotation * pointCamera + position;
  }
  cv::Vec3d toCamera(const cv::Vec3d& pointVehicle) const {
    return rotation.t() * (pointVehicle - position);
  }
};

// Mounting angles, degrees, applied in this order to a camera that starts looking along +x
// (forward) with its image upright (camera x = -y vehicle, camera y = -z vehicle):
//   roll  about the optical axis, positive turns the camera clockwise as seen from behind it;
//   pitch raises the optical axis (negative looks down);
//   yaw   turns the optical axis left about +z (90 = looking left, 180 = looking back).
// rotation = Rz(yaw) * Ry(-pitch) * Rx(roll) * R_base.
struct MountAngles {
  double yawDeg = 0;
  double pitchDeg = 0;
  double rollDeg = 0;
};
cv::Matx33d rotationFromMountAngles(const MountAngles& angles);
// The inverse (pitch in [-90, 90]); rotationFromMountAngles() of the result gives `rotation` back.
MountAngles mountAnglesFromRotation(const cv::Matx33d& rotation);
// The rotation of a unit quaternion (w, x, y, z; Hamilton's convention, as ROS and Eigen write it).
cv::Matx33d rotationFromQuaternion(const cv::Vec4d& wxyz);

struct CameraCalibration {
  std::string name;
  ColourRole role = ColourRole::kSource;
  Intrinsics intrinsics;
  Pose pose;
  // The pixels that see the vehicle's own body (CV_8U of the image size, non-zero = body; see
  // vehicle_body.hpp); empty: none. The panorama never samples them.
  cv::Mat bodyMask;
};

struct Rig {
  std::vector<CameraCalibration> cameras;  // mosaic and panorama order: as listed in the config
};

}  // namespace surroundd::processing
