#include "processing/bowl_shape.hpp"

#include <cmath>

namespace surroundd::processing {

double BowlShape::height(double radiusM) const {
  if (radiusM <= floorRadiusM) return 0;
  const double s = std::min(radiusM, rimRadiusM) - floorRadiusM;
  const double span = rimRadiusM - floorRadiusM;
  return rimHeightM * (s / span) * (s / span);
}

std::optional<cv::Vec3d> BowlShape::intersect(const cv::Vec3d& origin,
                                              const cv::Vec3d& direction) const {
  const double horizontal = std::hypot(direction[0], direction[1]);
  const double h = origin[2];
  if (horizontal < 1e-12) {
    if (direction[2] < 0) return cv::Vec3d(0, 0, 0);
    return std::nullopt;
  }
  // Along the ray, height is linear in the distance r from the axis: z(r) = h + slope * r.
  const double slope = direction[2] / horizontal;
  double r = 0;
  if (slope < 0 && -h / slope <= floorRadiusM) {
    r = -h / slope;
  } else {
    // Wall: h + slope * (floor + s) = k s^2 with k = rimHeight / span^2; the larger root is the
    // crossing outwards (the ray starts above the floor, the wall is convex and rising).
    const double span = rimRadiusM - floorRadiusM;
    const double k = rimHeightM / (span * span);
    const double c = h + slope * floorRadiusM;
    const double s = (slope + std::sqrt(slope * slope + 4 * k * c)) / (2 * k);
    r = s <= span ? floorRadiusM + s : rimRadiusM;
  }
  const double t = r / horizontal;
  return origin + t * direction;
}

}  // namespace surroundd::processing
