#include "tools/bench/panorama_accuracy.hpp"

#include <cmath>

#include "processing/camera_model.hpp"

namespace surroundd::bench {
namespace {

// Where a camera pixel's ray meets the ground, vehicle frame; nullopt for a ray that does not
// go down.
std::optional<cv::Vec3d> groundPoint(const processing::CameraModel& model,
                                     const processing::Pose& pose, const cv::Point2d& pixel) {
  const auto ray = model.unproject(pixel);
  if (!ray) return std::nullopt;
  const cv::Vec3d direction = pose.rotation * *ray;
  if (direction[2] >= -1e-9) return std::nullopt;
  return pose.position + (-pose.position[2] / direction[2]) * direction;
}

}  // namespace

SeamAlignment measureGroundSeams(const processing::Rig& rig,
                                 const processing::PanoramaSettings& settings,
                                 const processing::PanoramaLut& lut) {
  const processing::PanoramaProjector projector(rig, settings);
  const auto& geometry = settings.geometry;
  std::vector<processing::CameraModel> models;
  for (const auto& camera : rig.cameras) models.emplace_back(camera.intrinsics);

  SeamAlignment result;
  double sum = 0;
  for (const auto& blend : lut.blendTaps) {
    const auto width = static_cast<std::uint32_t>(lut.size.width);
    const std::uint32_t row = blend.pixel / width;
    const cv::Point2d pixel(blend.pixel % width, row);
    // Only where the panorama centre looks at the ground inside the floor: that is where the
    // ground is the scene (the bowl's wall stands for everything further away).
    const auto floor = settings.bowl.intersect(geometry.centre, geometry.direction(pixel));
    if (!floor || (*floor)[2] > 1e-9) continue;
    const std::size_t cameras[2] = {lut.taps[blend.pixel].camera, blend.tap.camera};
    std::optional<cv::Point2d> seen[2];
    for (int i = 0; i < 2; ++i) {
      const auto at = projector.cameraPixel(cameras[i], pixel);
      if (!at) break;
      const auto ground = groundPoint(models[cameras[i]], rig.cameras[cameras[i]].pose, *at);
      if (!ground) break;
      seen[i] = geometry.pixel(*ground - geometry.centre);
    }
    if (!seen[0] || !seen[1]) continue;
    double dx = std::abs(seen[0]->x - seen[1]->x);
    dx = std::min(dx, geometry.size.width - dx);  // across the +-180 degree column
    const double distance = std::hypot(dx, seen[0]->y - seen[1]->y);
    sum += distance;
    result.maxPx = std::max(result.maxPx, distance);
    ++result.samples;
  }
  result.meanPx = result.samples > 0 ? sum / result.samples : 0;
  return result;
}

cv::Mat trueGroundMask(const synth::Scene& scene, const synth::VehiclePose& pose,
                       const processing::PanoramaSettings& settings) {
  const auto& geometry = settings.geometry;
  cv::Mat mask(geometry.size, CV_8U, cv::Scalar(0));
  const cv::Vec3d origin = pose.toWorld(geometry.centre);
  for (int v = 0; v < geometry.size.height; ++v) {
    for (int u = 0; u < geometry.size.width; ++u) {
      const cv::Vec3d direction =
          geometry.direction({static_cast<double>(u), static_cast<double>(v)});
      const auto floor = settings.bowl.intersect(geometry.centre, direction);
      if (!floor || (*floor)[2] > 1e-9) continue;
      const synth::Hit hit =
          scene.intersect(cv::Vec3f(origin), cv::Vec3f(pose.directionToWorld(direction)));
      if (hit.surface == synth::Surface::kGround) mask.at<std::uint8_t>(v, u) = 255;
    }
  }
  return mask;
}

double meanAbsoluteError(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  cv::Mat difference;
  cv::absdiff(a, b, difference);
  const cv::Scalar mean = cv::mean(difference, mask);
  return (mean[0] + mean[1] + mean[2]) / a.channels();
}

}  // namespace surroundd::bench
