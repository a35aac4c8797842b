#include "processing/calibration/extrinsic_calibration.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include <fmt/format.h>
#include <opencv2/calib3d.hpp>

namespace surroundd::processing {
namespace {

// X_camera = rotation * X_vehicle + translation: what PnP solves for (the inverse of a Pose).
struct CameraFromVehicle {
  cv::Matx33d rotation;
  cv::Vec3d translation;
};

// A rotation into a virtual camera frame whose optical axis is `axis` (camera frame).
cv::Matx33d virtualFrameAround(const cv::Vec3d& axis) {
  const cv::Vec3d z = cv::normalize(axis);
  const cv::Vec3d helper = std::abs(z[1]) < 0.9 ? cv::Vec3d(0, 1, 0) : cv::Vec3d(1, 0, 0);
  const cv::Vec3d x = cv::normalize(helper.cross(z));
  const cv::Vec3d y = z.cross(x);
  return {x[0], x[1], x[2], y[0], y[1], y[2], z[0], z[1], z[2]};
}

// The first pose: RANSAC over P3P in a virtual pinhole looking along the mean ray, where every
// point within 80 degrees of that axis has normalized coordinates, whatever the real lens.
CameraFromVehicle initialPose(const Intrinsics& intrinsics, const std::vector<cv::Vec3d>& rays,
                              std::span<const PointCorrespondence> points,
                              const ExtrinsicSettings& settings) {
  cv::Vec3d sum(0, 0, 0);
  for (const auto& ray : rays) sum += ray;
  const cv::Matx33d toVirtual = virtualFrameAround(sum);
  const double minCos = std::cos(80 * std::numbers::pi / 180);
  std::vector<cv::Point3d> objects;
  std::vector<cv::Point2d> normalized;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const cv::Vec3d v = toVirtual * rays[i];
    if (v[2] < minCos) continue;
    objects.emplace_back(points[i].vehicle);
    normalized.emplace_back(v[0] / v[2], v[1] / v[2]);
  }
  if (static_cast<int>(objects.size()) < kMinimumPosePoints) {
    throw CalibrationError(fmt::format(
        "the points spread over more than 160 degrees of the field; only {} of {} lie within 80 "
        "degrees of their mean direction, at least {} are needed there",
        objects.size(), points.size(), kMinimumPosePoints));
  }
  // Threshold in normalized units; generous, since RANSAC only has to throw out gross mismatches:
  // off the virtual axis a pixel spans less than 1 / f of normalized distance.
  const cv::Vec2d focal = CameraModel(intrinsics).axisFocalPx();  // ocam has no fx, fy
  const double threshold = 4 * settings.inlierThresholdPx / std::min(focal[0], focal[1]);
  cv::Vec3d rvec, tvec;
  std::vector<int> inliers;
  const bool solved = cv::solvePnPRansac(
      objects, normalized, cv::Matx33d::eye(), cv::noArray(), rvec, tvec, false,
      settings.ransacIterations, static_cast<float>(threshold), 0.999, inliers, cv::SOLVEPNP_AP3P);
  if (!solved || static_cast<int>(inliers.size()) < kMinimumPosePoints) {
    throw CalibrationError(fmt::format(
        "no pose fits the points ({} of {} agree with the best one); check that every point's "
        "vehicle position matches its pixel",
        inliers.size(), objects.size()));
  }
  cv::Matx33d rotation;
  cv::Rodrigues(rvec, rotation);
  return {toVirtual.t() * rotation, toVirtual.t() * tvec};
}

double huberCost(double residual, double k) {
  return residual <= k ? 0.5 * residual * residual : k * (residual - 0.5 * k);
}

// Levenberg-Marquardt on the Huber-weighted reprojection error of the `active` points, through
// the real lens model. Parameters: a rotation increment applied on the left and a translation
// increment; Jacobian by central differences (six parameters, a few hundred points).
class PoseRefiner {
 public:
  PoseRefiner(const CameraModel& model, std::span<const PointCorrespondence> points, double huberPx)
      : model_(model), points_(points), huber_(huberPx) {}

  CameraFromVehicle refine(CameraFromVehicle pose, const std::vector<bool>& active) const {
    double lambda = 1e-3;
    double cost = totalCost(pose, active);
    for (int iteration = 0; iteration < 100; ++iteration) {
      cv::Matx66d normal = cv::Matx66d::zeros();
      cv::Vec6d gradient(0, 0, 0, 0, 0, 0);
      for (std::size_t i = 0; i < points_.size(); ++i) {
        if (!active[i]) continue;
        const auto r = residual(pose, i);
        if (!r) continue;
        const double norm = std::hypot(r->x, r->y);
        const double weight = norm <= huber_ ? 1.0 : huber_ / norm;
        cv::Matx<double, 2, 6> jacobian;
        for (int p = 0; p < 6; ++p) {
          constexpr double kStep = 1e-6;
          const auto plus = residual(step(pose, p, kStep), i);
          const auto minus = residual(step(pose, p, -kStep), i);
          if (!plus || !minus) continue;
          jacobian(0, p) = (plus->x - minus->x) / (2 * kStep);
          jacobian(1, p) = (plus->y - minus->y) / (2 * kStep);
        }
        normal += weight * jacobian.t() * jacobian;
        gradient += weight * jacobian.t() * cv::Vec2d(r->x, r->y);
      }
      bool improved = false;
      while (!improved && lambda < 1e12) {
        cv::Matx66d damped = normal;
        for (int p = 0; p < 6; ++p) damped(p, p) *= 1 + lambda;
        cv::Vec6d delta;
        if (!cv::solve(damped, -gradient, delta, cv::DECOMP_CHOLESKY)) break;
        const CameraFromVehicle candidate = apply(pose, delta);
        const double candidateCost = totalCost(candidate, active);
        if (candidateCost < cost) {
          improved = true;
          const double gain = cost - candidateCost;
          pose = candidate;
          cost = candidateCost;
          lambda = std::max(lambda / 10, 1e-9);
          if (gain < 1e-14 * (1 + cost) || cv::norm(delta) < 1e-12) return pose;
        } else {
          lambda *= 10;
        }
      }
      if (!improved) break;
    }
    return pose;
  }

  std::optional<cv::Point2d> residual(const CameraFromVehicle& pose, std::size_t i) const {
    const auto pixel = model_.project(pose.rotation * points_[i].vehicle + pose.translation);
    if (!pixel) return std::nullopt;
    return *pixel - points_[i].pixel;
  }

  double totalCost(const CameraFromVehicle& pose, const std::vector<bool>& active) const {
    // A point that leaves the lens's field costs as much as a far outlier.
    const double lost = huberCost(1e3, huber_);
    double cost = 0;
    for (std::size_t i = 0; i < points_.size(); ++i) {
      if (!active[i]) continue;
      const auto r = residual(pose, i);
      cost += r ? huberCost(std::hypot(r->x, r->y), huber_) : lost;
    }
    return cost;
  }

 private:
  // delta[0..2]: a rotation vector about the camera's own centre (radians), so that turning the
  // camera does not move it; delta[3..5]: a translation in the camera frame (metres).
  static CameraFromVehicle apply(CameraFromVehicle pose, const cv::Vec6d& delta) {
    cv::Matx33d turn;
    cv::Rodrigues(cv::Vec3d(delta[0], delta[1], delta[2]), turn);
    pose.rotation = turn * pose.rotation;
    pose.translation = turn * pose.translation + cv::Vec3d(delta[3], delta[4], delta[5]);
    return pose;
  }
  static CameraFromVehicle step(const CameraFromVehicle& pose, int parameter, double amount) {
    cv::Vec6d delta(0, 0, 0, 0, 0, 0);
    delta[parameter] = amount;
    return apply(pose, delta);
  }

  const CameraModel& model_;
  std::span<const PointCorrespondence> points_;
  double huber_;
};

}  // namespace

ExtrinsicCalibration calibrateExtrinsics(const Intrinsics& intrinsics,
                                         std::span<const PointCorrespondence> points,
                                         const ExtrinsicSettings& settings) {
  if (static_cast<int>(points.size()) < kMinimumPosePoints) {
    throw CalibrationError(
        fmt::format("too few points: {} marker corners or listed points, at "
                    "least {} are needed",
                    points.size(), kMinimumPosePoints));
  }
  const CameraModel model(intrinsics);
  std::vector<cv::Vec3d> rays;
  for (const auto& point : points) {
    const auto ray = model.unproject(point.pixel);
    if (!ray) {
      throw CalibrationError(fmt::format("{}: pixel ({:.1f}, {:.1f}) is outside the lens's field",
                                         point.label, point.pixel.x, point.pixel.y));
    }
    rays.push_back(*ray);
  }
  const PoseRefiner refiner(model, points, settings.huberPx);
  std::vector<bool> active(points.size(), true);
  CameraFromVehicle pose = refiner.refine(initialPose(intrinsics, rays, points, settings), active);
  if (settings.prior) {
    const Pose& prior = *settings.prior;
    const CameraFromVehicle fromPrior =
        refiner.refine({prior.rotation.t(), -(prior.rotation.t() * prior.position)}, active);
    if (refiner.totalCost(fromPrior, active) < refiner.totalCost(pose, active)) pose = fromPrior;
  }

  ExtrinsicCalibration result;
  const auto classify = [&] {
    result.inlierCount = 0;
    result.reprojected.clear();
    result.inlier.clear();
    double sumSquares = 0;
    for (std::size_t i = 0; i < points.size(); ++i) {
      const auto r = refiner.residual(pose, i);
      const bool inlier = r && std::hypot(r->x, r->y) <= settings.inlierThresholdPx;
      constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
      result.reprojected.push_back(r ? points[i].pixel + *r : cv::Point2d(kNan, kNan));
      result.inlier.push_back(inlier);
      if (!inlier) continue;
      ++result.inlierCount;
      sumSquares += r->dot(*r);
    }
    result.rmsPx = result.inlierCount > 0 ? std::sqrt(sumSquares / result.inlierCount) : 0;
  };
  classify();
  if (result.inlierCount < kMinimumPosePoints) {
    throw CalibrationError(fmt::format(
        "only {} of {} points are within {} px of the best pose, at least {} are needed",
        result.inlierCount, points.size(), settings.inlierThresholdPx, kMinimumPosePoints));
  }
  pose = refiner.refine(pose, result.inlier);
  classify();
  result.pose.rotation = pose.rotation.t();
  result.pose.position = -(pose.rotation.t() * pose.translation);
  return result;
}

}  // namespace surroundd::processing
