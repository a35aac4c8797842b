#include "processing/stitch/panorama_lut.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "common/camera_limit.hpp"
#include "common/work_pool.hpp"

namespace surroundd::processing {
namespace {

constexpr double kTwoPi = 2 * std::numbers::pi;

// Counter-clockwise angle from a to b, in (0, 2 pi].
double ccw(double a, double b) {
  const double d = std::fmod(b - a, kTwoPi);
  return d <= 0 ? d + kTwoPi : d;
}

double absAngle(double a) { return std::abs(std::remainder(a, kTwoPi)); }

// Which cameras a column of the panorama uses: its owner (the sector it lies in), the neighbour
// across the nearer seam and the distance to that seam, and every camera by distance of its axis,
// for pixels that the owner does not see.
struct ColumnPlan {
  std::uint8_t owner = 0;
  std::uint8_t neighbour = 0;
  double seamDistanceRad = 0;
  std::vector<std::uint8_t> byDistance;
};

std::vector<ColumnPlan> planColumns(const PanoramaProjector& projector) {
  const std::size_t n = projector.cameraCount();
  std::vector<std::uint8_t> sorted(n);
  std::iota(sorted.begin(), sorted.end(), std::uint8_t{0});
  std::ranges::sort(sorted, {}, [&](std::uint8_t c) { return projector.axisAzimuth(c); });
  // seams[k]: between sorted[k] and sorted[k + 1], on the bisector of their axes.
  std::vector<double> seams(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double a = projector.axisAzimuth(sorted[k]);
    seams[k] = a + ccw(a, projector.axisAzimuth(sorted[(k + 1) % n])) / 2;
  }
  const auto& geometry = projector.settings().geometry;
  std::vector<ColumnPlan> columns(static_cast<std::size_t>(geometry.size.width));
  for (int u = 0; u < geometry.size.width; ++u) {
    const double azimuth = geometry.azimuth(u);
    ColumnPlan& plan = columns[static_cast<std::size_t>(u)];
    plan.byDistance = sorted;
    std::ranges::sort(plan.byDistance, {},
                      [&](std::uint8_t c) { return absAngle(azimuth - projector.axisAzimuth(c)); });
    if (n == 1) {
      plan.owner = plan.neighbour = sorted[0];
      plan.seamDistanceRad = std::numbers::pi;
      continue;
    }
    for (std::size_t k = 0; k < n; ++k) {
      const double leftSeam = seams[(k + n - 1) % n];
      const double toLeft = ccw(leftSeam, azimuth);
      if (toLeft >= ccw(leftSeam, seams[k])) continue;
      const double toRight = ccw(azimuth, seams[k]);
      plan.owner = sorted[k];
      plan.neighbour = toLeft < toRight ? sorted[(k + n - 1) % n] : sorted[(k + 1) % n];
      plan.seamDistanceRad = std::min(toLeft, toRight);
      break;
    }
  }
  return columns;
}

// Whether camera `camera`, which the LUT takes nothing from, would show part of its sector but
// for its body mask: then the rig is sound, the camera sees only its own car there.
bool hiddenByBody(const Rig& rig, const PanoramaSettings& settings,
                  const std::vector<ColumnPlan>& columns, std::size_t camera) {
  if (rig.cameras[camera].bodyMask.empty()) return false;
  Rig bare = rig;
  bare.cameras[camera].bodyMask = cv::Mat();
  const PanoramaProjector withoutBody(bare, settings);
  const cv::Size size = settings.geometry.size;
  constexpr int kStep = 4;  // a coarse look is enough to tell none from some
  for (int u = 0; u < size.width; u += kStep) {
    if (columns[static_cast<std::size_t>(u)].owner != camera) continue;
    for (int v = 0; v < size.height; v += kStep) {
      if (withoutBody.cameraPixel(camera, cv::Point2d(u, v))) return true;
    }
  }
  return false;
}

}  // namespace

LutTap encodeTap(const cv::Point2d& p, cv::Size size, std::uint8_t camera) {
  constexpr int kOne = LutTap::kFractionOne;
  // The 2x2 neighbourhood must stay inside the image: at the last column or row, interpolate
  // from the one before with a full fraction.
  int x0 = std::min(static_cast<int>(std::floor(p.x)), size.width - 2);
  int y0 = std::min(static_cast<int>(std::floor(p.y)), size.height - 2);
  auto fx = static_cast<int>(std::lround((p.x - x0) * kOne));
  auto fy = static_cast<int>(std::lround((p.y - y0) * kOne));
  if (fx == kOne && x0 < size.width - 2) ++x0, fx = 0;
  if (fy == kOne && y0 < size.height - 2) ++y0, fy = 0;
  return {static_cast<std::uint32_t>(y0 * size.width + x0), static_cast<std::uint8_t>(fx),
          static_cast<std::uint8_t>(fy), camera, 0};
}

PanoramaProjector::PanoramaProjector(const Rig& rig, const PanoramaSettings& settings)
    : settings_(settings) {
  for (const auto& camera : rig.cameras) {
    models_.emplace_back(camera.intrinsics);
    poses_.push_back(camera.pose);
    cv::Mat grown;
    if (!camera.bodyMask.empty()) {
      cv::dilate(camera.bodyMask, grown,
                 cv::getStructuringElement(cv::MORPH_RECT,
                                           cv::Size(2 * kBodyMargin + 1, 2 * kBodyMargin + 1)));
    }
    bodyMasks_.push_back(grown);
    // The optical axis seen from above; a camera looking straight down is placed by its mount.
    const cv::Vec3d axis(camera.pose.rotation(0, 2), camera.pose.rotation(1, 2),
                         camera.pose.rotation(2, 2));
    axisAzimuth_.push_back(std::hypot(axis[0], axis[1]) > 1e-3
                               ? std::atan2(axis[1], axis[0])
                               : std::atan2(camera.pose.position[1], camera.pose.position[0]));
  }
}

cv::Vec3d PanoramaProjector::surfacePoint(const cv::Point2d& panoramaPixel) const {
  const cv::Vec3d direction = settings_.geometry.direction(panoramaPixel);
  const cv::Vec3d& centre = settings_.geometry.centre;
  if (settings_.projection == PanoramaProjection::kSphere) return centre + direction;
  // Only a ray straight up misses the bowl, and no panorama row looks straight up.
  return settings_.bowl.intersect(centre, direction).value_or(centre + direction);
}

std::optional<cv::Point2d> PanoramaProjector::cameraPixel(std::size_t camera,
                                                          const cv::Point2d& panoramaPixel) const {
  const Pose& pose = poses_[camera];
  if (settings_.projection != PanoramaProjection::kSphere) {
    return cameraPixelOf(camera, surfacePoint(panoramaPixel));
  }
  return visiblePixel(camera, pose.rotation.t() * settings_.geometry.direction(panoramaPixel));
}

std::optional<cv::Point2d> PanoramaProjector::cameraPixelOf(std::size_t camera,
                                                            const cv::Vec3d& point) const {
  return visiblePixel(camera, poses_[camera].toCamera(point));
}

std::optional<cv::Point2d> PanoramaProjector::visiblePixel(std::size_t camera,
                                                           const cv::Vec3d& pointCamera) const {
  const auto pixel = models_[camera].project(pointCamera);
  const cv::Size size = models_[camera].intrinsics().imageSize;
  if (!pixel || pixel->x < 0 || pixel->y < 0 || pixel->x > size.width - 1 ||
      pixel->y > size.height - 1) {
    return std::nullopt;
  }
  const cv::Mat& body = bodyMasks_[camera];
  if (!body.empty() && body.at<std::uint8_t>(static_cast<int>(std::lround(pixel->y)),
                                             static_cast<int>(std::lround(pixel->x))) != 0) {
    return std::nullopt;
  }
  return pixel;
}

PanoramaLut buildPanoramaLut(const Rig& rig, const PanoramaSettings& settings, WorkPool& pool,
                             const LutProgress& progress) {
  // A tap's camera is a byte beside kUnseen; every camera a rig may have fits it.
  static_assert(kMaxCameras < PanoramaLut::kUnseen);
  if (rig.cameras.empty() || rig.cameras.size() > kMaxCameras) {
    throw std::invalid_argument(
        fmt::format("a panorama needs 1 to {} cameras, not {}", kMaxCameras, rig.cameras.size()));
  }
  const PanoramaProjector projector(rig, settings);
  const std::vector<ColumnPlan> columns = planColumns(projector);
  const cv::Size size = settings.geometry.size;
  const std::size_t n = rig.cameras.size();

  PanoramaLut lut;
  lut.size = size;
  for (const auto& camera : rig.cameras) lut.cameraSizes.push_back(camera.intrinsics.imageSize);
  lut.taps.resize(static_cast<std::size_t>(size.area()));
  std::vector<std::vector<BlendTap>> blendRows(static_cast<std::size_t>(size.height));
  // Pixels each camera contributes to, per row (rows are built in parallel).
  std::vector<int> used(static_cast<std::size_t>(size.height) * n, 0);

  const auto buildRow = [&](int v) {
    const auto row = static_cast<std::size_t>(v);
    for (int u = 0; u < size.width; ++u) {
      const ColumnPlan& plan = columns[static_cast<std::size_t>(u)];
      const cv::Point2d pixel(u, v);
      const std::size_t index = row * static_cast<std::size_t>(size.width) + u;
      LutTap& tap = lut.taps[index];
      tap = {0, 0, 0, PanoramaLut::kUnseen, 0};
      const auto own = projector.cameraPixel(plan.owner, pixel);
      if (own) {
        tap = encodeTap(*own, lut.cameraSizes[plan.owner], plan.owner);
        const double weight = 0.5 - plan.seamDistanceRad / settings.featherRad;
        const auto share = static_cast<int>(std::lround(weight * 256));
        if (share > 0 && plan.neighbour != plan.owner) {
          if (const auto other = projector.cameraPixel(plan.neighbour, pixel)) {
            LutTap blend = encodeTap(*other, lut.cameraSizes[plan.neighbour], plan.neighbour);
            blend.weight = static_cast<std::uint8_t>(share);
            blendRows[row].push_back({static_cast<std::uint32_t>(index), blend});
            ++used[row * n + plan.neighbour];
          }
        }
      } else {
        for (const std::uint8_t camera : plan.byDistance) {
          if (camera == plan.owner) continue;
          if (const auto other = projector.cameraPixel(camera, pixel)) {
            tap = encodeTap(*other, lut.cameraSizes[camera], camera);
            break;
          }
        }
      }
      if (tap.camera != PanoramaLut::kUnseen) ++used[row * n + tap.camera];
    }
  };

  constexpr int kProgressSteps = 10;
  for (int step = 0; step < kProgressSteps; ++step) {
    const int first = size.height * step / kProgressSteps;
    const int last = size.height * (step + 1) / kProgressSteps;
    pool.parallelFor(
        last - first,
        [&](int begin, int end) {
          for (int v = first + begin; v < first + end; ++v) buildRow(v);
        },
        pool.threads() * 4);
    if (progress) progress(static_cast<double>(last) / size.height);
  }

  lut.blendRowBegin.reserve(static_cast<std::size_t>(size.height) + 1);
  for (const auto& blendRow : blendRows) {
    lut.blendRowBegin.push_back(static_cast<std::uint32_t>(lut.blendTaps.size()));
    lut.blendTaps.insert(lut.blendTaps.end(), blendRow.begin(), blendRow.end());
  }
  lut.blendRowBegin.push_back(static_cast<std::uint32_t>(lut.blendTaps.size()));

  for (std::size_t camera = 0; camera < n; ++camera) {
    int total = 0;
    for (int v = 0; v < size.height; ++v) total += used[static_cast<std::size_t>(v) * n + camera];
    if (total == 0 && !hiddenByBody(rig, settings, columns, camera)) {
      throw RigError(fmt::format(
          "camera '{}' contributes nothing to the panorama (elevation {:.1f} to {:.1f} deg): it "
          "sees none of it, or only what other cameras see nearer their axes; check its mount",
          rig.cameras[camera].name, settings.geometry.elevationTopRad * 180 / std::numbers::pi,
          settings.geometry.elevationBottomRad * 180 / std::numbers::pi));
    }
  }
  return lut;
}

cv::Mat PanoramaLut::ownerMap() const {
  cv::Mat owner(size, CV_8U);
  auto* out = owner.ptr<std::uint8_t>();
  for (std::size_t i = 0; i < taps.size(); ++i) out[i] = taps[i].camera;
  return owner;
}

std::vector<std::size_t> PanoramaLut::camerasWithoutTaps() const {
  std::vector<char> sampled(cameraSizes.size(), 0);
  for (const LutTap& tap : taps) {
    if (tap.camera != kUnseen) sampled[tap.camera] = 1;
  }
  for (const BlendTap& blend : blendTaps) sampled[blend.tap.camera] = 1;
  std::vector<std::size_t> without;
  for (std::size_t camera = 0; camera < sampled.size(); ++camera) {
    if (sampled[camera] == 0) without.push_back(camera);
  }
  return without;
}

cv::Mat PanoramaLut::validMask() const {
  cv::Mat mask;
  cv::compare(ownerMap(), cv::Scalar(kUnseen), mask, cv::CMP_NE);
  return mask;
}

}  // namespace surroundd::processing
