#include "processing/camera_model.hpp"

#include <algorithm>
#include <cmath>

namespace surroundd::processing {
namespace {

// Radial distortion polynomials and their derivatives in the radial variable.
struct Radial {
  double value;       // distorted radius
  double derivative;  // d value / d radius
};

Radial pinholeRadial(const std::array<double, 5>& d, double r) {
  const double r2 = r * r;
  const double poly = 1 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
  const double polyDerivative = r2 * (2 * d[0] + r2 * (4 * d[1] + r2 * 6 * d[4]));
  return {r * poly, poly + polyDerivative};
}

Radial fisheyeRadial(const std::array<double, 5>& d, double theta) {
  const double t2 = theta * theta;
  const double poly = 1 + t2 * (d[0] + t2 * (d[1] + t2 * (d[2] + t2 * d[3])));
  const double polyDerivative = t2 * (2 * d[0] + t2 * (4 * d[1] + t2 * (6 * d[2] + t2 * 8 * d[3])));
  return {theta * poly, poly + polyDerivative};
}

// Largest radius (pinhole: normalized image radius; fisheye: field angle) up to `limit` over which
// the radial mapping keeps increasing: beyond it two rays would share a pixel, so the lens is
// treated as ending there.
template <typename RadialFn>
double monotonicLimit(RadialFn radial, double limit) {
  constexpr int kSteps = 4000;
  for (int i = 1; i <= kSteps; ++i) {
    const double r = limit * i / kSteps;
    if (radial(r).derivative <= 0) return limit * (i - 1) / kSteps;
  }
  return limit;
}

// Pinhole rays are accepted up to this normalized radius (about 84 degrees off axis).
constexpr double kPinholeMaxRadius = 10.0;

}  // namespace

CameraModel::CameraModel(const Intrinsics& intrinsics) : intrinsics_(intrinsics) {
  const auto& d = intrinsics_.distortion;
  if (intrinsics_.model == LensModel::kPinhole) {
    maxRadius_ = monotonicLimit([&](double r) { return pinholeRadial(d, r); }, kPinholeMaxRadius);
  } else {
    intrinsics_.maxFieldAngleRad =
        monotonicLimit([&](double t) { return fisheyeRadial(d, t); }, intrinsics_.maxFieldAngleRad);
    maxRadius_ = fisheyeRadial(d, intrinsics_.maxFieldAngleRad).value;
  }
}

std::optional<cv::Point2d> CameraModel::project(const cv::Vec3d& p) const {
  const auto& in = intrinsics_;
  const auto& d = in.distortion;
  double xd = 0;
  double yd = 0;
  if (in.model == LensModel::kPinhole) {
    if (p[2] <= 0) return std::nullopt;
    const double x = p[0] / p[2];
    const double y = p[1] / p[2];
    const double r2 = x * x + y * y;
    if (r2 > maxRadius_ * maxRadius_) return std::nullopt;
    const double radial = 1 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
    xd = x * radial + 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x);
    yd = y * radial + d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y;
  } else {
    const double planar = std::hypot(p[0], p[1]);
    const double theta = std::atan2(planar, p[2]);
    if (theta > in.maxFieldAngleRad) return std::nullopt;
    if (planar > 0) {
      const double scale = fisheyeRadial(d, theta).value / planar;
      xd = p[0] * scale;
      yd = p[1] * scale;
    }
  }
  return cv::Point2d(in.fx * xd + in.cx, in.fy * yd + in.cy);
}

std::optional<cv::Vec3d> CameraModel::unproject(const cv::Point2d& pixel) const {
  const auto& in = intrinsics_;
  const auto& d = in.distortion;
  const double xd = (pixel.x - in.cx) / in.fx;
  const double yd = (pixel.y - in.cy) / in.fy;
  if (in.model == LensModel::kFisheye) {
    const double thetaD = std::hypot(xd, yd);
    // The edge of the field itself belongs to the lens; allow for rounding in project().
    if (thetaD > maxRadius_ * (1 + 1e-12)) return std::nullopt;
    if (thetaD == 0) return cv::Vec3d(0, 0, 1);
    // Newton on theta_d(theta) = thetaD; the mapping is monotonic on [0, maxFieldAngle].
    double theta = thetaD;
    for (int i = 0; i < 30; ++i) {
      const Radial f = fisheyeRadial(d, theta);
      const double step = (f.value - thetaD) / f.derivative;
      theta = std::clamp(theta - step, 0.0, in.maxFieldAngleRad);
      if (std::abs(step) < 1e-15) break;
    }
    const double s = std::sin(theta) / thetaD;
    return cv::Vec3d(xd * s, yd * s, std::cos(theta));
  }
  // Pinhole: Newton on the 2D distortion map, starting from the distorted point.
  double x = xd;
  double y = yd;
  for (int i = 0; i < 50; ++i) {
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
    const double dRadial = 2 * d[0] + r2 * (4 * d[1] + r2 * 6 * d[4]);  // d radial / d r2
    const double fx = x * radial + 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x) - xd;
    const double fy = y * radial + d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y - yd;
    const double j00 = radial + 2 * x * x * dRadial + 2 * d[2] * y + 6 * d[3] * x;
    const double j01 = 2 * x * y * dRadial + 2 * d[2] * x + 2 * d[3] * y;
    const double j10 = 2 * x * y * dRadial + 2 * d[2] * x + 2 * d[3] * y;
    const double j11 = radial + 2 * y * y * dRadial + 6 * d[2] * y + 2 * d[3] * x;
    const double det = j00 * j11 - j01 * j10;
    if (std::abs(det) < 1e-12) return std::nullopt;
    const double dx = (j11 * fx - j01 * fy) / det;
    const double dy = (j00 * fy - j10 * fx) / det;
    x -= dx;
    y -= dy;
    if (std::abs(dx) + std::abs(dy) < 1e-15) break;
  }
  if (x * x + y * y > maxRadius_ * maxRadius_) return std::nullopt;
  // A pixel outside the distortion's image has no preimage: Newton then stalls off target.
  const auto back = project(cv::Vec3d(x, y, 1));
  if (!back || std::hypot(back->x - pixel.x, back->y - pixel.y) > 1e-6) return std::nullopt;
  return cv::normalize(cv::Vec3d(x, y, 1));
}

bool CameraModel::inImage(const cv::Point2d& pixel) const {
  // Pixel centres are at integer coordinates, so the image covers [-0.5, size - 0.5).
  return pixel.x >= -0.5 && pixel.y >= -0.5 && pixel.x < intrinsics_.imageSize.width - 0.5 &&
         pixel.y < intrinsics_.imageSize.height - 0.5;
}

}  // namespace surroundd::processing
