#include "processing/camera_model.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <fmt/format.h>
#include <fmt/ranges.h>

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

// Largest radius (pinhole: normalized image radius; fisheye, ocam: field angle) up to `limit` over
// which the radial mapping keeps increasing: beyond it two rays would share a pixel, so the lens
// is treated as ending there.
template <typename RadialFn>
double monotonicLimit(RadialFn radial, double limit) {
  constexpr int kSteps = 4000;
  for (int i = 1; i <= kSteps; ++i) {
    const double r = limit * i / kSteps;
    if (radial(r).derivative <= 0) return limit * (i - 1) / kSteps;
  }
  return limit;
}

// The off-axis angle in [0, limit] where an increasing radial mapping reaches `target`: Newton,
// with a bisection step whenever Newton would leave the bracket, so a polynomial that is nearly
// flat somewhere (OCamCalib fits often are near their edge) still converges.
template <typename RadialFn>
double invertRadial(RadialFn radial, double target, double guess, double limit) {
  double low = 0;
  double high = limit;
  double x = std::clamp(guess, low, high);
  for (int i = 0; i < 100; ++i) {
    const Radial f = radial(x);
    const double error = f.value - target;
    if (error == 0) break;
    (error < 0 ? low : high) = x;
    double next = x - error / f.derivative;
    if (!(next > low && next < high)) next = (low + high) / 2;
    const bool converged = std::abs(next - x) < 1e-15;
    x = next;
    if (converged) break;
  }
  return x;
}

// Pinhole rays are accepted up to this normalized radius (about 84 degrees off axis).
constexpr double kPinholeMaxRadius = 10.0;

}  // namespace

CameraModel::CameraModel(const Intrinsics& intrinsics) : intrinsics_(intrinsics) {
  const auto& d = intrinsics_.distortion;
  const auto& ocam = intrinsics_.ocam;
  double askedRad = 0;
  double fieldRad = 0;
  double edgeRadius = 0;  // distorted radius at the edge of the field, as sensorRadius() gives it
  switch (intrinsics_.model) {
    case LensModel::kPinhole:
      askedRad = std::atan(kPinholeMaxRadius);
      maxRadius_ = monotonicLimit([&](double r) { return pinholeRadial(d, r); }, kPinholeMaxRadius);
      fieldRad = std::atan(maxRadius_);
      edgeRadius = pinholeRadial(d, maxRadius_).value;
      break;
    case LensModel::kFisheye:
      // No ray is further than 180 degrees off axis, whatever the field asks for.
      askedRad = std::min(intrinsics_.maxFieldAngleRad, std::numbers::pi);
      fieldRad = monotonicLimit([&](double t) { return fisheyeRadial(d, t); }, askedRad);
      maxRadius_ = edgeRadius = fisheyeRadial(d, fieldRad).value;
      intrinsics_.maxFieldAngleRad = fieldRad;
      break;
    case LensModel::kOcam:
      askedRad = std::min(intrinsics_.maxFieldAngleRad, std::numbers::pi);
      fieldRad =
          monotonicLimit([&](double a) { return ocamRadial(ocam.worldToImage, a); }, askedRad);
      maxRadius_ = edgeRadius = ocamRadial(ocam.worldToImage, fieldRad).value;
      axisRho_ = ocamRadial(ocam.worldToImage, 0).value;
      intrinsics_.maxFieldAngleRad = fieldRad;
      break;
  }
  if (fieldRad < askedRad) {
    const cv::Size size = intrinsics_.imageSize;
    bool inImage = false;
    for (const cv::Point2d corner :
         {cv::Point2d(-0.5, -0.5), cv::Point2d(size.width - 0.5, -0.5),
          cv::Point2d(-0.5, size.height - 0.5), cv::Point2d(size.width - 0.5, size.height - 0.5)}) {
      inImage = inImage || sensorRadius(corner) > edgeRadius;
    }
    fieldCut_ = FieldCut{fieldRad, askedRad, inImage};
  }
}

cv::Point2d CameraModel::sensorPoint(const cv::Point2d& pixel) const {
  const auto& in = intrinsics_;
  if (in.model != LensModel::kOcam) return {(pixel.x - in.cx) / in.fx, (pixel.y - in.cy) / in.fy};
  // [u - xc; v - yc] = [c d; e 1] [x; y], inverted. By hand: with Eigen's Matrix2d (inverse()
  // here, the product in project()) sensorRadius() over a 1280x960 image took 23.2 ms against
  // 18.5, project() of 1.2 million rays 93 against 88 ms (one core of the 2-core desk machine,
  // medians of 5 alternating runs).
  const auto& a = in.ocam;
  const double det = a.c - a.d * a.e;
  const double du = pixel.x - in.cx;
  const double dv = pixel.y - in.cy;
  return {(du - a.d * dv) / det, (a.c * dv - a.e * du) / det};
}

double CameraModel::sensorRadius(const cv::Point2d& pixel) const {
  const cv::Point2d m = sensorPoint(pixel);
  return std::hypot(m.x, m.y);
}

cv::Vec2d CameraModel::axisFocalPx() const {
  const auto& in = intrinsics_;
  if (in.model != LensModel::kOcam) return {in.fx, in.fy};
  const double slope = ocamRadial(in.ocam.worldToImage, 0).derivative;  // pixels per radian
  return {slope * std::hypot(in.ocam.c, in.ocam.e), slope * std::hypot(in.ocam.d, 1.0)};
}

std::optional<cv::Point2d> CameraModel::project(const cv::Vec3d& p) const {
  const auto& in = intrinsics_;
  if (in.model == LensModel::kOcam) {
    const double planar = std::hypot(p[0], p[1]);
    const double offAxis = std::atan2(planar, p[2]);
    if (offAxis > in.maxFieldAngleRad) return std::nullopt;
    // On the axis the direction of rho is undefined (and rho itself all but 0).
    if (planar == 0) return cv::Point2d(in.cx, in.cy);
    const double rho = ocamRadial(in.ocam.worldToImage, offAxis).value;
    const double x = p[0] / planar * rho;
    const double y = p[1] / planar * rho;
    const auto& a = in.ocam;
    return cv::Point2d(a.c * x + a.d * y + in.cx, a.e * x + y + in.cy);
  }
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
  if (in.model == LensModel::kOcam) return unprojectOcam(pixel);
  const auto& d = in.distortion;
  const cv::Point2d sensor = sensorPoint(pixel);
  const double xd = sensor.x;
  const double yd = sensor.y;
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
  // Pinhole: Newton on the 2D distortion map, starting from the distorted point. The 2x2 step by
  // Cramer's rule: with Eigen's Matrix2d and inverse() unprojecting every pixel of a 1280x720
  // lens (a body mask's work) took 140 ms against 109 (medians of 5 alternating runs, one core).
  double x = xd;
  double y = yd;
  for (int i = 0; i < 50; ++i) {
    const double r2 = x * x + y * y;
    const double radial = 1 + r2 * (d[0] + r2 * (d[1] + r2 * d[4]));
    const double dRadial = d[0] + r2 * (2 * d[1] + r2 * 3 * d[4]);  // d radial / d r2
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

std::optional<cv::Vec3d> CameraModel::unprojectOcam(const cv::Point2d& pixel) const {
  const auto& a = intrinsics_.ocam;
  if (a.c - a.d * a.e == 0) return std::nullopt;
  const cv::Point2d m = sensorPoint(pixel);
  const double rho = std::hypot(m.x, m.y);
  // The edge of the field itself belongs to the lens; allow for rounding in project().
  if (rho > maxRadius_ * (1 + 1e-12)) return std::nullopt;
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
  const double field = intrinsics_.maxFieldAngleRad;
  const double offAxis = invertRadial([&](double t) { return ocamRadial(a.worldToImage, t); }, rho,
                                      field * rho / maxRadius_, field);
  const double s = std::sin(offAxis) / rho;
  return cv::Vec3d(m.x * s, m.y * s, std::cos(offAxis));
}

bool CameraModel::inImage(const cv::Point2d& pixel) const {
  // Pixel centres are at integer coordinates, so the image covers [-0.5, size - 0.5).
  return pixel.x >= -0.5 && pixel.y >= -0.5 && pixel.x < intrinsics_.imageSize.width - 0.5 &&
         pixel.y < intrinsics_.imageSize.height - 0.5;
}

std::string lensKey(const Intrinsics& intrinsics) {
  // As many names as Intrinsics (and its Ocam) has members: one more there is an error here.
  const auto& [model, imageSize, fx, fy, cx, cy, distortion, maxFieldAngleRad, ocam] = intrinsics;
  const auto& [c, d, e, worldToImage, imageToWorld] = ocam;
  return fmt::format(
      "{} {}x{} f {:a} {:a} c {:a} {:a} d {:a} fov {:a} ocam {:a} {:a} {:a} world to image {:a} "
      "image to world {:a}",
      lensModelName(model), imageSize.width, imageSize.height, fx, fy, cx, cy,
      fmt::join(distortion, " "), maxFieldAngleRad, c, d, e, fmt::join(worldToImage, " "),
      fmt::join(imageToWorld, " "));
}

}  // namespace surroundd::processing
