#include "processing/lens/ocam_lens.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace surroundd::processing {
namespace {

// OCamCalib's rho(theta) as a function of the off-axis angle: theta, the elevation below the sensor
// plane, is the off-axis angle less 90 degrees (atan(-1 / r) = atan2(-z, |xy|) for z > 0, and the
// same formula carries on past 90 degrees without a jump).
Radial ocamRadial(const std::vector<double>& p, double offAxis) {
  const double theta = offAxis - std::numbers::pi / 2;
  Radial f{0, 0};
  for (auto it = p.rbegin(); it != p.rend(); ++it) {  // Horner, with the derivative alongside
    f.derivative = f.derivative * theta + f.value;
    f.value = f.value * theta + *it;
  }
  return f;
}

}  // namespace

OcamLens::OcamLens(const Intrinsics& in) : cx_(in.cx), cy_(in.cy), ocam_(in.ocam) {
  const auto radial = [&](double a) { return ocamRadial(ocam_.worldToImage, a); };
  field_.askedRad = std::min(in.maxFieldAngleRad, std::numbers::pi);
  field_.fieldRad = monotonicLimit(radial, field_.askedRad);
  field_.edgeRadius = radial(field_.fieldRad).value;
  axisRho_ = radial(0).value;
}

cv::Point2d OcamLens::sensorPoint(const cv::Point2d& pixel) const {
  // [u - xc; v - yc] = [c d; e 1] [x; y], inverted. By hand: with Eigen's Matrix2d (inverse()
  // here, the product in project()) the radii over a 1280x960 image took 23.2 ms against 18.5,
  // project() of 1.2 million rays 93 against 88 ms (one core of the 2-core desk machine, medians
  // of 5 alternating runs).
  const auto& a = ocam_;
  const double det = a.c - a.d * a.e;
  const double du = pixel.x - cx_;
  const double dv = pixel.y - cy_;
  return {(du - a.d * dv) / det, (a.c * dv - a.e * du) / det};
}

cv::Vec2d OcamLens::axisFocalPx() const {
  const double slope = ocamRadial(ocam_.worldToImage, 0).derivative;  // pixels per radian
  return {slope * std::hypot(ocam_.c, ocam_.e), slope * std::hypot(ocam_.d, 1.0)};
}

std::optional<cv::Point2d> OcamLens::project(const cv::Vec3d& p) const {
  const double planar = std::hypot(p[0], p[1]);
  const double offAxis = std::atan2(planar, p[2]);
  if (offAxis > field_.fieldRad) return std::nullopt;
  // On the axis the direction of rho is undefined (and rho itself all but 0).
  if (planar == 0) return cv::Point2d(cx_, cy_);
  const double rho = ocamRadial(ocam_.worldToImage, offAxis).value;
  const double x = p[0] / planar * rho;
  const double y = p[1] / planar * rho;
  const auto& a = ocam_;
  return cv::Point2d(a.c * x + a.d * y + cx_, a.e * x + y + cy_);
}

std::optional<cv::Vec3d> OcamLens::unproject(const cv::Point2d& pixel) const {
  const auto& a = ocam_;
  if (a.c - a.d * a.e == 0) return std::nullopt;
  const cv::Point2d m = sensorPoint(pixel);
  const double rho = std::hypot(m.x, m.y);
  // The edge of the field itself belongs to the lens; allow for rounding in project().
  if (rho > field_.edgeRadius * (1 + 1e-12)) return std::nullopt;
  if (!a.imageToWorld.empty()) {
    double z = 0;
    for (auto it = a.imageToWorld.rbegin(); it != a.imageToWorld.rend(); ++it) z = z * rho + *it;
    // OCamCalib's sensor frame has z towards the back of the lens: its (x, y, z) is OpenCV's
    // (x, y, -z), as project() takes theta = atan2(-z, |xy|).
    const cv::Vec3d ray(m.x, m.y, -z);
    if (cv::norm(ray) == 0) return std::nullopt;
    return cv::normalize(ray);
  }
  // A fitted rho(theta) misses 0 on the axis by a hundredth of a pixel or so: pixels that close to
  // the centre take the axis.
  if (rho <= std::max(axisRho_, 0.0)) return cv::Vec3d(0, 0, 1);
  const double field = field_.fieldRad;
  const double offAxis = invertRadial([&](double t) { return ocamRadial(a.worldToImage, t); }, rho,
                                      field * rho / field_.edgeRadius, field);
  const double s = std::sin(offAxis) / rho;
  return cv::Vec3d(m.x * s, m.y * s, std::cos(offAxis));
}

}  // namespace surroundd::processing
