#include "tools/calibrate/import/source_frame.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace surroundd::calibrate {

double SourceFrame::groundFor(const std::string& camera) const {
  const auto it = groundZByCamera.find(camera);
  return it == groundZByCamera.end() ? groundZ : it->second;
}

int SourceFrame::verticalAxis() const {
  for (int axis = 0; axis < 3; ++axis) {
    if (std::abs(axes(2, axis)) > 0.5) return axis;
  }
  return 2;  // the options only allow axis-aligned frames, so one column is vertical
}

double SourceFrame::verticalSign() const { return axes(2, verticalAxis()) > 0 ? 1.0 : -1.0; }

processing::Pose vehiclePose(const SourceFrame& frame, const std::string& camera,
                             const CameraFromSource& pose) {
  // Camera centre in the source frame: P_camera = 0 at C = -R^T t.
  const cv::Vec3d centre = -(pose.rotation.t() * pose.translation);
  cv::Vec3d groundPoint;
  groundPoint[frame.verticalAxis()] = frame.groundFor(camera);
  processing::Pose vehicle;
  vehicle.position = frame.unitM * (frame.axes * (centre - groundPoint));
  // Columns of R^T are the camera axes in the source frame; the axes matrix turns them.
  vehicle.rotation = frame.axes * pose.rotation.t();
  return vehicle;
}

cv::Vec3d boundingBoxCentre(const std::vector<processing::Pose>& poses) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  cv::Vec2d low(kInf, kInf), high(-kInf, -kInf);
  for (const auto& pose : poses) {
    for (int i = 0; i < 2; ++i) {
      low[i] = std::min(low[i], pose.position[i]);
      high[i] = std::max(high[i], pose.position[i]);
    }
  }
  if (poses.empty()) return {};
  return {(low[0] + high[0]) / 2, (low[1] + high[1]) / 2, 0};
}

}  // namespace surroundd::calibrate
