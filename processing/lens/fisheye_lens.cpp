#include "processing/lens/fisheye_lens.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace surroundd::processing {
namespace {

Radial fisheyeRadial(const std::array<double, 5>& d, double theta) {
  const double t2 = theta * theta;
  const double poly = 1 + t2 * (d[0] + t2 * (d[1] + t2 * (d[2] + t2 * d[3])));
  const double polyDerivative = t2 * (2 * d[0] + t2 * (4 * d[1] + t2 * (6 * d[2] + t2 * 8 * d[3])));
  return {theta * poly, poly + polyDerivative};
}

}  // namespace

FisheyeLens::FisheyeLens(const Intrinsics& in) : plane_(in), d_(in.distortion) {
  // No ray is further than 180 degrees off axis, whatever the field asks for.
  field_.askedRad = std::min(in.maxFieldAngleRad, std::numbers::pi);
  field_.fieldRad = monotonicLimit([&](double t) { return fisheyeRadial(d_, t); }, field_.askedRad);
  field_.edgeRadius = fisheyeRadial(d_, field_.fieldRad).value;
}

std::optional<cv::Point2d> FisheyeLens::project(const cv::Vec3d& p) const {
  const double planar = std::hypot(p[0], p[1]);
  const double theta = std::atan2(planar, p[2]);
  if (theta > field_.fieldRad) return std::nullopt;
  double xd = 0;
  double yd = 0;
  if (planar > 0) {
    const double scale = fisheyeRadial(d_, theta).value / planar;
    xd = p[0] * scale;
    yd = p[1] * scale;
  }
  return plane_.pixel(xd, yd);
}

std::optional<cv::Vec3d> FisheyeLens::unproject(const cv::Point2d& pixel) const {
  const cv::Point2d sensor = sensorPoint(pixel);
  const double thetaD = std::hypot(sensor.x, sensor.y);
  // The edge of the field itself belongs to the lens; allow for rounding in project().
  if (thetaD > field_.edgeRadius * (1 + 1e-12)) return std::nullopt;
  if (thetaD == 0) return cv::Vec3d(0, 0, 1);
  // Newton on theta_d(theta) = thetaD; the mapping is monotonic on [0, the field's edge].
  double theta = thetaD;
  for (int i = 0; i < 30; ++i) {
    const Radial f = fisheyeRadial(d_, theta);
    const double step = (f.value - thetaD) / f.derivative;
    theta = std::clamp(theta - step, 0.0, field_.fieldRad);
    if (std::abs(step) < 1e-15) break;
  }
  const double s = std::sin(theta) / thetaD;
  return cv::Vec3d(sensor.x * s, sensor.y * s, std::cos(theta));
}

}  // namespace surroundd::processing
