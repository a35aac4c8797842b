#include "daemon/config/camera_calibration_yaml.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string_view>

#include <fmt/format.h>

#include "processing/lens/camera_model.hpp"

namespace surroundd::daemon {
namespace {

using processing::LensModel;

constexpr double kDegToRad = std::numbers::pi / 180.0;

// OCamCalib's own parameters (lens.model ocam); cx_px, cy_px are its distortion centre.
void readOcam(YamlObject& lens, processing::Intrinsics& in) {
  auto& ocam = in.ocam;
  if (const auto affine = lens.numbers("affine", {3})) {
    ocam.c = (*affine)[0], ocam.d = (*affine)[1], ocam.e = (*affine)[2];
    // Singular, or a mirror image: neither is a lens, and unproject() divides by it.
    if (!(ocam.c - ocam.d * ocam.e > 1e-3)) {
      lens.error("affine",
                 fmt::format("expected [c, d, e] of an invertible matrix [c d; e 1] that keeps the "
                             "image's orientation (c - d e > 0, near 1), got c - d e = {:.6g}",
                             ocam.c - ocam.d * ocam.e));
    }
  }
  if (const auto p = lens.numbers("world_to_image", 2, 32)) {
    ocam.worldToImage = *p;
  } else if (!lens.has("world_to_image")) {
    lens.errorHere("missing key 'world_to_image' (OCamCalib's inverse polynomial p0, p1, ...)");
  }
  if (const auto a = lens.numbers("image_to_world", 2, 32)) {
    ocam.imageToWorld = *a;
    if (!(a->front() < 0)) {
      lens.error("image_to_world",
                 fmt::format("expected OCamCalib's a0 < 0 first (z in front of the lens is "
                             "negative in its frame), got {:.6g}",
                             a->front()));
    }
  }
}

// The largest distortion coefficient taken. Radial terms multiply powers of the normalized radius
// (about 1 at a wide lens's picture edge), so a coefficient of 1000 already moves the edge by three
// orders of magnitude: real calibrations stay far below (OpenCV's k3 of a wide lens: tens at most).
constexpr double kMaxDistortion = 1000;
// At the picture's edge, the distortion may widen or narrow the lens's field by at most this
// factor against the same lens without it (a 220-degree fisheye against its pinhole: under 2).
constexpr double kMaxFieldChange = 4;

// Distortion that no lens has, which would otherwise pass --check-config and fail at start (the
// camera seeing a pinpoint, or nothing): each coefficient finite and within kMaxDistortion, and the
// picture's left and right edges at an off-axis angle near the undistorted lens's.
void checkDistortion(YamlObject& lens, std::string_view camera, const processing::Intrinsics& in) {
  const bool fisheye = in.model == LensModel::kFisheye;
  constexpr std::array<const char*, 5> kPinholeNames{"k1", "k2", "p1", "p2", "k3"};
  constexpr std::array<const char*, 4> kFisheyeNames{"k1", "k2", "k3", "k4"};
  for (std::size_t i = 0; i < (fisheye ? 4U : 5U); ++i) {
    const double k = in.distortion[i];
    if (!(std::abs(k) <= kMaxDistortion)) {
      lens.error("distortion",
                 fmt::format("camera '{}': {} = {:g} is no lens's distortion (expected within "
                             "-{:g} to {:g})",
                             camera, fisheye ? kFisheyeNames[i] : kPinholeNames[i], k,
                             kMaxDistortion, kMaxDistortion));
      return;
    }
  }
  const processing::CameraModel model(in);
  for (const double x : {-0.5, in.imageSize.width - 0.5}) {
    const cv::Point2d edge(x, in.cy);
    const auto ray = model.unproject(edge);
    if (!ray) continue;  // beyond where the polynomial turns: lensFieldCutWarning says so
    const double angle = std::acos(std::clamp((*ray)[2] / cv::norm(*ray), -1.0, 1.0));
    const double undistorted = std::atan(std::abs(x - in.cx) / in.fx);
    if (undistorted < 1e-6) continue;
    if (!(angle <= undistorted * kMaxFieldChange && angle * kMaxFieldChange >= undistorted)) {
      constexpr double kRadToDeg = 180 / std::numbers::pi;
      lens.error("distortion",
                 fmt::format("camera '{}': with this distortion the picture's edge is {:.3g} "
                             "degrees off axis, where the lens without it sees {:.3g}; no lens "
                             "distorts that much (check the calibration's units and order)",
                             camera, angle * kRadToDeg, undistorted * kRadToDeg));
      return;
    }
  }
}

}  // namespace

processing::Intrinsics readLens(YamlObject& lens, std::string_view camera) {
  processing::Intrinsics in;
  static constexpr auto kModels = [] {
    std::array<std::pair<std::string_view, LensModel>, processing::kLensModels.size()> named{};
    for (std::size_t i = 0; i < named.size(); ++i) {
      named[i] = {lensModelName(processing::kLensModels[i]), processing::kLensModels[i]};
    }
    return named;
  }();
  in.model = lens.choice("model", LensModel::kPinhole,
                         std::span<const std::pair<std::string_view, LensModel>>(kModels));
  const int width = lens.requiredInteger("width_px", 16, 16384).value_or(0);
  const int height = lens.requiredInteger("height_px", 16, 16384).value_or(0);
  in.imageSize = cv::Size(width, height);
  const bool ocam = in.model == LensModel::kOcam;
  if (ocam) {
    for (const auto key : {"fx_px", "fy_px", "distortion"}) {
      if (lens.has(key)) {
        lens.error(key, "an ocam lens does not take this key (world_to_image is its projection)");
      }
    }
  } else {
    in.fx = lens.requiredNumber("fx_px", {0.0, 1e6, true, "pixels"}).value_or(1.0);
    in.fy = lens.requiredNumber("fy_px", {0.0, 1e6, true, "pixels"}).value_or(1.0);
  }
  in.cx = lens.requiredNumber("cx_px",
                              {0.0, std::max(width, 1) * 1.0, false, "pixels, inside the image"})
              .value_or(0.0);
  in.cy = lens.requiredNumber("cy_px",
                              {0.0, std::max(height, 1) * 1.0, false, "pixels, inside the image"})
              .value_or(0.0);
  const bool fisheye = in.model == LensModel::kFisheye;
  if (ocam) {
    readOcam(lens, in);
  } else {
    const auto distortion =
        fisheye ? lens.numbers("distortion", {4}) : lens.numbers("distortion", {4, 5});
    if (distortion) {
      std::copy(distortion->begin(), distortion->end(), in.distortion.begin());
      if (in.fx > 0 && in.imageSize.width > 0) checkDistortion(lens, camera, in);
    }
    for (const auto key : {"affine", "world_to_image", "image_to_world"}) {
      if (lens.has(key)) lens.error(key, "only an ocam lens takes this key");
    }
  }
  if (fisheye || ocam) {
    in.maxFieldAngleRad =
        lens.number("field_of_view_deg", 180.0, {0.0, 360.0, true, "degrees, full field"}) *
        kDegToRad / 2;
  } else if (lens.has("field_of_view_deg")) {
    lens.error("field_of_view_deg",
               "only a fisheye or ocam lens takes this key (a pinhole sees less than 180 degrees)");
  }
  lens.finish();
  return in;
}

processing::Pose readMount(YamlObject& mount) {
  processing::Pose pose;
  const NumberRange metres{-100.0, 100.0, false, "metres, vehicle frame"};
  pose.position = {mount.requiredNumber("x_m", metres).value_or(0.0),
                   mount.requiredNumber("y_m", metres).value_or(0.0),
                   mount.requiredNumber("z_m", metres).value_or(0.0)};
  const bool angles = mount.has("yaw_deg") || mount.has("pitch_deg") || mount.has("roll_deg");
  if (mount.has("quaternion_wxyz")) {
    if (angles)
      mount.errorHere("give either yaw_deg/pitch_deg/roll_deg or quaternion_wxyz, not both");
    if (const auto q = mount.numbers("quaternion_wxyz", {4})) {
      const cv::Vec4d wxyz((*q)[0], (*q)[1], (*q)[2], (*q)[3]);
      const double norm = cv::norm(wxyz);
      if (std::abs(norm - 1.0) > 1e-3) {
        mount.error("quaternion_wxyz",
                    fmt::format("expected a unit quaternion (a rotation), got norm {:.6g}", norm));
      } else {
        pose.rotation = processing::rotationFromQuaternion(wxyz / norm);
      }
    }
  } else {
    const NumberRange degrees{-360.0, 360.0, false, "degrees"};
    pose.rotation = processing::rotationFromMountAngles({mount.number("yaw_deg", 0.0, degrees),
                                                         mount.number("pitch_deg", 0.0, degrees),
                                                         mount.number("roll_deg", 0.0, degrees)});
  }
  mount.finish();
  return pose;
}

}  // namespace surroundd::daemon
