#pragma once
// A foreign calibration's frame, as the user states it on the command line, and the step from a
// pose in that frame to the camera's pose in the project's vehicle frame (origin on the ground
// under the vehicle centre, x forward, y left, z up, metres).

#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "processing/rig.hpp"

namespace surroundd::calibrate {

// A rigid transform P_camera = rotation * P_source + translation, in source units.
struct CameraFromSource {
  cv::Matx33d rotation = cv::Matx33d::eye();
  cv::Vec3d translation;
};

struct SourceFrame {
  cv::Matx33d axes = cv::Matx33d::eye();  // columns: source x, y, z in the vehicle frame
  double unitM = 1;                       // metres per source unit
  double groundZ = 0;                     // on the vertical source axis, source units
  std::map<std::string, double> groundZByCamera;

  double groundFor(const std::string& camera) const;
  // The source axis (0, 1, 2) that is vertical, and +1 when it points up, -1 when down.
  int verticalAxis() const;
  double verticalSign() const;
};

// The camera's pose in the vehicle frame, before any origin shift: the source origin dropped onto
// the ground lands on the vehicle origin.
processing::Pose vehiclePose(const SourceFrame& frame, const std::string& camera,
                             const CameraFromSource& pose);

// The centre of the bounding box of the positions, in x and y (z = 0): what --origin-centre
// subtracts.
cv::Vec3d boundingBoxCentre(const std::vector<processing::Pose>& poses);

}  // namespace surroundd::calibrate
