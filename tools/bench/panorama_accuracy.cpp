#include "tools/bench/panorama_accuracy.hpp"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "processing/lens/camera_model.hpp"

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

double seamColourStep(const cv::Mat& panorama, const processing::PanoramaLut& lut,
                      double featherRad, const cv::Mat& mask, int window) {
  const int width = lut.size.width;
  const cv::Mat owner = lut.ownerMap();
  const cv::Mat valid = lut.validMask() & mask;
  const int gap = static_cast<int>(std::ceil(featherRad / 2 * width / (2 * CV_PI))) + 1;
  // Seam columns: where the owner along the row that most cameras see changes.
  const cv::Mat anySeen = lut.validMask();
  int bestRow = 0;
  for (int v = 0; v < lut.size.height; ++v) {
    if (cv::countNonZero(anySeen.row(v)) > cv::countNonZero(anySeen.row(bestRow))) bestRow = v;
  }
  std::vector<int> seams;
  for (int u = 0; u < width; ++u) {
    if (owner.at<std::uint8_t>(bestRow, u) != owner.at<std::uint8_t>(bestRow, (u + 1) % width)) {
      seams.push_back(u + 1);
    }
  }
  double sum = 0;
  int bands = 0;
  for (const int seam : seams) {
    for (int top = 0; top + window <= lut.size.height; top += window) {
      cv::Vec3d sides[2];
      bool seen = true;
      for (int side = 0; side < 2 && seen; ++side) {
        const int first = side == 0 ? seam - gap - window : seam + gap;
        for (int v = top; v < top + window && seen; ++v) {
          for (int k = 0; k < window; ++k) {
            const int u = (first + k + width) % width;
            if (valid.at<std::uint8_t>(v, u) == 0) {
              seen = false;
              break;
            }
            sides[side] += cv::Vec3d(panorama.at<cv::Vec3b>(v, u));
          }
        }
      }
      if (!seen) continue;
      const cv::Vec3d step = (sides[0] - sides[1]) / (window * window);
      sum += (std::abs(step[0]) + std::abs(step[1]) + std::abs(step[2])) / 3;
      ++bands;
    }
  }
  return bands > 0 ? sum / bands : 0;
}

double seamColourError(const cv::Mat& panorama, const std::vector<cv::Mat>& frames,
                       const processing::Rig& rig, const processing::PanoramaSettings& settings,
                       const processing::PanoramaLut& lut, const cv::Mat& mask, int window,
                       int reach) {
  const processing::PanoramaProjector projector(rig, settings);
  double sum = 0;
  int tiles = 0;
  for (int top = 0; top + window <= lut.size.height; top += window) {
    for (int left = 0; left + window <= lut.size.width; left += window) {
      const std::uint8_t source =
          lut.taps[static_cast<std::size_t>(top) * lut.size.width + left].camera;
      if (source == processing::PanoramaLut::kUnseen ||
          rig.cameras[source].role != processing::ColourRole::kSource) {
        continue;
      }
      const auto ownerAt = [&](int u) {
        return lut
            .taps[static_cast<std::size_t>(top) * lut.size.width +
                  static_cast<std::size_t>((u + lut.size.width) % lut.size.width)]
            .camera;
      };
      for (std::size_t target = 0; target < rig.cameras.size(); ++target) {
        if (rig.cameras[target].role != processing::ColourRole::kTarget) continue;
        // Near a seam with this target: it owns a pixel within reach on either side.
        if (ownerAt(left - reach) != target && ownerAt(left + window - 1 + reach) != target) {
          continue;
        }
        cv::Vec3d panoramaSum;
        cv::Vec3d targetSum;
        bool inside = true;
        for (int v = top; v < top + window && inside; ++v) {
          for (int u = left; u < left + window && inside; ++u) {
            const auto at =
                projector.cameraPixel(target, {static_cast<double>(u), static_cast<double>(v)});
            inside = at.has_value() && mask.at<std::uint8_t>(v, u) != 0 &&
                     lut.taps[static_cast<std::size_t>(v) * lut.size.width + u].camera == source;
            if (!inside) break;
            cv::Mat sample;
            cv::getRectSubPix(frames[target], {1, 1}, cv::Point2f(*at), sample);
            targetSum += cv::Vec3d(sample.at<cv::Vec3b>(0, 0));
            panoramaSum += cv::Vec3d(panorama.at<cv::Vec3b>(v, u));
          }
        }
        if (!inside) continue;
        const cv::Vec3d difference = (panoramaSum - targetSum) / (window * window);
        sum += (std::abs(difference[0]) + std::abs(difference[1]) + std::abs(difference[2])) / 3;
        ++tiles;
      }
    }
  }
  return tiles > 0 ? sum / tiles : 0;
}

std::vector<cv::Mat> framesWithGains(const std::vector<cv::Mat>& frames,
                                     const std::vector<cv::Vec3f>& gains) {
  std::vector<cv::Mat> scaled(frames.size());
  for (std::size_t c = 0; c < frames.size(); ++c) {
    cv::multiply(frames[c], cv::Scalar(gains[c][0], gains[c][1], gains[c][2]), scaled[c]);
  }
  return scaled;
}

double meanAbsoluteError(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask) {
  cv::Mat difference;
  cv::absdiff(a, b, difference);
  const cv::Scalar mean = cv::mean(difference, mask);
  return (mean[0] + mean[1] + mean[2]) / a.channels();
}

}  // namespace surroundd::bench
