#pragma once
// The surface around the vehicle that the panorama stands for: a flat floor (the ground) out to
// floorRadius, then a wall rising as a parabola, z = rimHeight * ((r - floor) / (rim - floor))^2,
// to rimHeight at rimRadius, and above the rim a vertical cylinder of radius rimRadius. The bowl
// projection of the panorama and the bowl render mesh use this one shape, so that what the
// stitcher assumes about depth is what the viewer sees.

#include <optional>

#include <opencv2/core.hpp>

namespace surroundd::processing {

struct BowlShape {
  double floorRadiusM = 5.0;
  double rimRadiusM = 10.0;  // > floorRadiusM
  double rimHeightM = 3.0;   // > 0

  // Height of the surface at a distance r from the vehicle's z axis (r past the rim: the rim's
  // height, the cylinder's foot).
  double height(double radiusM) const;

  // Where the ray origin + t * direction (t > 0) meets the surface. `origin` must be on the z axis
  // above the ground (the panorama centre). Every ray does, except one straight up (nullopt).
  std::optional<cv::Vec3d> intersect(const cv::Vec3d& origin, const cv::Vec3d& direction) const;

  bool operator==(const BowlShape&) const = default;
};

}  // namespace surroundd::processing
