#include "tools/calibrate/ground_homography.hpp"

#include <cmath>

#include <fmt/format.h>

#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

CameraFromSource poseFromGroundHomography(const cv::Matx33d& homography, const cv::Matx33d& camera,
                                          const GroundCanvas& canvas, const std::string& origin) {
  const cv::Matx33d groundToCanvas(1 / canvas.scale, 0, canvas.origin.x, 0, 1 / canvas.scale,
                                   canvas.origin.y, 0, 0, 1);
  const cv::Matx33d m = camera.inv() * homography * groundToCanvas;
  const cv::Vec3d m1(m(0, 0), m(1, 0), m(2, 0)), m2(m(0, 1), m(1, 1), m(2, 1)),
      m3(m(0, 2), m(1, 2), m(2, 2));
  const double n1 = cv::norm(m1), n2 = cv::norm(m2);
  // Columns of a rotation have one length; a ratio far from 1 means the wrong K, scale or matrix.
  if (n1 < 1e-12 || n2 < 1e-12 || std::abs(n1 / n2 - 1) > 0.05 ||
      std::abs(m1.dot(m2)) / (n1 * n2) > 0.05) {
    throw UsageError(fmt::format(
        "{}: the homography is not the ground seen through the camera matrix (its rotation "
        "columns differ in length by {:.1f} % and are {:.1f} deg from perpendicular); check that "
        "H maps canvas pixels to image pixels, and --canvas-scale",
        origin, 100 * std::abs(n1 / std::max(n2, 1e-12) - 1),
        std::abs(90 - std::acos(std::clamp(m1.dot(m2) / std::max(n1 * n2, 1e-24), -1.0, 1.0)) *
                          180 / CV_PI)));
  }
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
    if (centre[2] * canvas.upSign <= 0) continue;  // the other sign: a camera under the ground
    return {rotation, translation - rotation * cv::Vec3d(0, 0, canvas.groundZ)};
  }
  throw UsageError(fmt::format("{}: the homography puts the camera on the ground plane", origin));
}

}  // namespace surroundd::calibrate
