#pragma once
// What every camera a reader accepts must satisfy, whatever text it came from: the rest of the
// daemon (camera model, LUT, mesh) takes these for granted and checks none of them again.

#include <cmath>
#include <span>

#include "daemon/config/rig_yaml.hpp"
#include "tests/fuzz/fuzz_support.hpp"

namespace surroundd::fuzz {

inline bool finite(double value) { return std::isfinite(value); }

inline bool intrinsicsAreSound(const processing::Intrinsics& lens) {
  if (lens.imageSize.width < 1 || lens.imageSize.height < 1) return false;
  if (!finite(lens.cx) || !finite(lens.cy) || !finite(lens.maxFieldAngleRad)) return false;
  for (const double k : lens.distortion) {
    if (!finite(k)) return false;
  }
  if (lens.model == processing::LensModel::kOcam) {
    if (lens.ocam.worldToImage.empty()) return false;
    for (const double p : lens.ocam.worldToImage) {
      if (!finite(p)) return false;
    }
    for (const double a : lens.ocam.imageToWorld) {
      if (!finite(a)) return false;
    }
    return finite(lens.ocam.c) && finite(lens.ocam.d) && finite(lens.ocam.e);
  }
  return finite(lens.fx) && finite(lens.fy) && lens.fx > 0 && lens.fy > 0;
}

// A rotation is orthonormal with determinant +1: anything else shears or mirrors the world.
inline bool poseIsSound(const processing::Pose& pose) {
  const cv::Matx33d shouldBeIdentity = pose.rotation.t() * pose.rotation;
  if (cv::norm(shouldBeIdentity - cv::Matx33d::eye()) > 1e-6) return false;
  if (std::abs(cv::determinant(pose.rotation) - 1.0) > 1e-6) return false;
  return finite(pose.position[0]) && finite(pose.position[1]) && finite(pose.position[2]);
}

// A finding when an accepted camera breaks what the daemon relies on.
inline void checkAcceptedCameras(std::span<const daemon::RigCamera> cameras) {
  for (const auto& camera : cameras) {
    FUZZ_CHECK(!camera.calibration.name.empty());
    FUZZ_CHECK(intrinsicsAreSound(camera.calibration.intrinsics));
    FUZZ_CHECK(poseIsSound(camera.calibration.pose));
  }
}

}  // namespace surroundd::fuzz
