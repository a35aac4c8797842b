#include "tools/calibrate/import/ground_homography.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {
namespace {

// Where the pixels of a grid over the image are sampled, per side.
constexpr int kSamplesAcross = 24;
// Ground farther than this many camera heights is left out: near the horizon H's ground points
// run off to infinity, and a homography clicked on nearby ground says nothing of it.
constexpr double kFarthestInHeights = 10;

// The camera from H = K [r1 r2 t] S^-1 (S: ground (x, y) to canvas pixels), the sign that puts it
// above the ground; none when the columns collapse or no sign does. The start of the fit only.
std::optional<CameraFromSource> decomposed(const cv::Matx33d& m, const GroundCanvas& canvas) {
  const cv::Vec3d m1(m(0, 0), m(1, 0), m(2, 0)), m2(m(0, 1), m(1, 1), m(2, 1)),
      m3(m(0, 2), m(1, 2), m(2, 2));
  const double n1 = cv::norm(m1), n2 = cv::norm(m2);
  if (n1 < 1e-12 || n2 < 1e-12) return std::nullopt;
  for (const double sign : {1.0, -1.0}) {
    const double lambda = sign * 2 / (n1 + n2);
    const cv::Vec3d r1 = lambda * m1, r2 = lambda * m2, r3 = r1.cross(r2);
    const cv::Matx33d approximate(r1[0], r2[0], r3[0], r1[1], r2[1], r3[1], r1[2], r2[2], r3[2]);
    // The nearest rotation (in the Frobenius sense) to the noisy [r1 r2 r1 x r2].
    cv::Mat w, u, vt;
    cv::SVD::compute(cv::Mat(approximate), w, u, vt);
    const cv::Matx33d rotation(cv::Mat(u * vt));
    const cv::Vec3d translation = lambda * m3;
    const cv::Vec3d centre = -(rotation.t() * translation);
    if (centre[2] * canvas.upSign > 0) return CameraFromSource{rotation, translation};
  }
  return std::nullopt;
}

}  // namespace

GroundPoseFit poseFromGroundHomography(const cv::Matx33d& homography, const cv::Matx33d& camera,
                                       cv::Size imageSize, const GroundCanvas& canvas,
                                       const std::string& origin) {
  // Ground (x, y) on the canvas plane, source units, in the plane's own frame (z = 0 on it).
  const cv::Matx33d groundToCanvas(1 / canvas.scale, 0, canvas.origin.x, 0, 1 / canvas.scale,
                                   canvas.origin.y, 0, 0, 1);
  const cv::Matx33d toGround = (homography * groundToCanvas).inv();
  const auto start = decomposed(camera.inv() * homography * groundToCanvas, canvas);
  if (!start) {
    throw UsageError(fmt::format(
        "{}: the homography is not the ground seen by a camera above it (it collapses, or puts "
        "the camera on or under the ground); check that H maps canvas pixels to image pixels, "
        "and --canvas-scale",
        origin));
  }
  const cv::Vec3d centre = -(start->rotation.t() * start->translation);
  const double height = std::abs(centre[2]);

  std::vector<cv::Point3d> ground;
  std::vector<cv::Point2d> pixels;
  for (int row = 0; row <= kSamplesAcross; ++row) {
    for (int column = 0; column <= kSamplesAcross; ++column) {
      const cv::Point2d pixel(column * (imageSize.width - 1.0) / kSamplesAcross,
                              row * (imageSize.height - 1.0) / kSamplesAcross);
      const cv::Vec3d g = toGround * cv::Vec3d(pixel.x, pixel.y, 1);
      if (std::abs(g[2]) < 1e-12) continue;
      const cv::Point3d point(g[0] / g[2], g[1] / g[2], 0);
      // In front of the decomposed camera, and near enough to be the ground H was made from.
      const cv::Vec3d inCamera =
          start->rotation * cv::Vec3d(point.x, point.y, 0) + start->translation;
      if (inCamera[2] <= 0 ||
          std::hypot(point.x - centre[0], point.y - centre[1]) > kFarthestInHeights * height) {
        continue;
      }
      ground.push_back(point);
      pixels.push_back(pixel);
    }
  }
  if (ground.size() < 6) {
    throw UsageError(fmt::format(
        "{}: the homography shows the camera too little ground ({} points of a {}x{} grid over "
        "the image, within {:g} camera heights) to fit its pose; check --canvas-scale",
        origin, ground.size(), kSamplesAcross + 1, kSamplesAcross + 1, kFarthestInHeights));
  }
  cv::Mat rvec, tvec(start->translation);
  cv::Rodrigues(cv::Mat(start->rotation), rvec);
  cv::solvePnP(ground, pixels, cv::Mat(camera), cv::noArray(), rvec, tvec, true,
               cv::SOLVEPNP_ITERATIVE);
  cv::Mat rotationMat;
  cv::Rodrigues(rvec, rotationMat);

  GroundPoseFit fit;
  const cv::Matx33d rotation(rotationMat);
  const cv::Vec3d translation(tvec);
  // How far the fitted camera is from H: in the image, and on the ground (each pixel's ray from
  // the fitted camera to the plane, against the ground point H gives it).
  std::vector<cv::Point2d> projected;
  cv::projectPoints(ground, rvec, tvec, cv::Mat(camera), cv::noArray(), projected);
  const cv::Vec3d fittedCentre = -(rotation.t() * translation);
  if (fittedCentre[2] * canvas.upSign <= 0) {
    throw UsageError(fmt::format(
        "{}: the camera that best explains the homography is under the ground", origin));
  }
  double pixelSquares = 0, groundSquares = 0;
  for (std::size_t i = 0; i < ground.size(); ++i) {
    pixelSquares += std::pow(cv::norm(projected[i] - pixels[i]), 2);
    const cv::Vec3d ray = rotation.t() * (camera.inv() * cv::Vec3d(pixels[i].x, pixels[i].y, 1));
    const double along = std::abs(ray[2]) > 1e-12 ? -fittedCentre[2] / ray[2] : 0;
    const cv::Vec3d onGround = fittedCentre + along * ray;
    groundSquares += std::pow(std::hypot(onGround[0] - ground[i].x, onGround[1] - ground[i].y), 2);
  }
  fit.points = static_cast<int>(ground.size());
  fit.rmsPx = std::sqrt(pixelSquares / static_cast<double>(ground.size()));
  fit.rmsGroundUnits = std::sqrt(groundSquares / static_cast<double>(ground.size()));
  // From the plane's frame (z = 0 on it) to the source's (the plane at z = groundZ).
  fit.pose = {rotation, translation - rotation * cv::Vec3d(0, 0, canvas.groundZ)};
  return fit;
}

}  // namespace surroundd::calibrate
