#include "daemon/rig_yaml.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>
#include <numbers>
#include <set>
#include <span>

#include <fmt/format.h>

#include "capture/sequence_pattern.hpp"
#include "common/camera_limit.hpp"
#include "processing/camera_model.hpp"

namespace surroundd::daemon {
namespace {

using processing::LensModel;

constexpr double kDegToRad = std::numbers::pi / 180.0;

// An image sequence pattern ("front_%06d.png") names no single file; check that its first frame
// exists, with FFmpeg's image2 default start numbers.
bool sequenceExists(const std::filesystem::path& pattern) {
  for (int index = 0; index <= 4; ++index) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(capture::sequenceFrameName(pattern.string(), index), ec)) {
      return true;
    }
  }
  return false;
}

constexpr std::array<std::pair<std::string_view, capture::PixelLayout>, 2> kPreloadFormats{{
    {"yuyv", capture::PixelLayout::kYuyv},
    {"nv12", capture::PixelLayout::kNv12},
}};

// A file source's `preload` and `format`: the pixel format its frames are held in, or nullopt when
// it is decoded as it plays.
std::optional<capture::PixelLayout> readPreload(YamlObject& source) {
  const bool preload = source.boolean("preload", false);
  if (!preload && source.has("format")) {
    source.error("format",
                 "expected only with 'preload: true' (the pixel format preloaded frames "
                 "are held in), got it without");
    return std::nullopt;
  }
  if (!preload) return std::nullopt;
  return source.choice(
      "format", capture::PixelLayout::kYuyv,
      std::span<const std::pair<std::string_view, capture::PixelLayout>>(kPreloadFormats));
}

// A live camera delivers its own frames: `preload` belongs to a file source only.
void refusePreload(YamlObject& source, std::string_view kind) {
  if (source.has("preload")) {
    source.error("preload",
                 fmt::format("expected only in a file source (a recording preloaded into "
                             "memory), got it in a {} camera's",
                             kind));
  }
}

// A source whose file is wrong is still returned (its error is already recorded), so that the
// camera is not reported a second time as having no source.
capture::FileSourceSettings readSource(YamlObject& source,
                                       std::optional<capture::PixelLayout>& preload) {
  capture::FileSourceSettings settings;
  const auto path = source.outputPath("file");
  // A still picture is a camera only if it repeats; a video or a sequence plays once by default.
  settings.loop = source.boolean("loop", path && capture::isStillPicturePath(*path));
  settings.sequenceFps =
      source.number("sequence_fps", 30.0, {0.0, 1000.0, true, "frames per second"});
  preload = readPreload(source);
  source.finish();
  if (!path) return settings;
  settings.path = *path;
  std::error_code ec;
  const capture::FileNameKind kind = capture::classifyFileName(path->string());
  if (kind == capture::FileNameKind::kTooWide) {
    source.error("file", fmt::format("expected an image sequence pattern with %d or %0Nd (N up to "
                                     "{}), got '{}' (its number is wider than that)",
                                     capture::kMaxSequenceDigits, path->string()));
  } else if (kind == capture::FileNameKind::kSequence) {
    if (!sequenceExists(*path)) {
      source.error(
          "file",
          fmt::format("expected an image sequence, got '{}' (its first frame does not exist)",
                      path->string()));
    }
  } else if (!std::filesystem::is_regular_file(*path, ec)) {
    source.error(
        "file",
        fmt::format("expected an existing video file or picture, got '{}' ({})", path->string(),
                    std::filesystem::exists(*path, ec) ? "not a regular file" : "no such file"));
  }
  return settings;
}

constexpr std::array<std::pair<std::string_view, capture::V4l2Format>, 5> kV4l2Formats{{
    {"auto", capture::V4l2Format::kAuto},
    {"yuyv", capture::V4l2Format::kYuyv},
    {"uyvy", capture::V4l2Format::kUyvy},
    {"nv12", capture::V4l2Format::kNv12},
    {"mjpeg", capture::V4l2Format::kMjpeg},
}};
constexpr std::array<std::string_view, 8> kV4l2Controls{"exposure_auto",
                                                        "exposure_absolute",
                                                        "gain",
                                                        "white_balance_auto",
                                                        "white_balance_temperature",
                                                        "brightness",
                                                        "contrast",
                                                        "saturation"};

// A live camera; its size is the lens's (set by the caller), its device path is taken as written
// (a /dev path, not relative to the file).
capture::V4l2Settings readDevice(YamlObject& source) {
  capture::V4l2Settings settings;
  settings.device = source.string("device", "");
  refusePreload(source, "V4L2");
  settings.format = source.choice(
      "format", settings.format,
      std::span<const std::pair<std::string_view, capture::V4l2Format>>(kV4l2Formats));
  settings.fps = source.number("fps", settings.fps, {1.0, 1000.0, false, "frames per second"});
  settings.buffers = source.integer("buffers", settings.buffers, 2, 32);
  settings.timeout = std::chrono::milliseconds(source.integer("timeout_ms", 500, 20, 60'000));
  if (auto controls = source.object("controls")) {
    for (const auto name : kV4l2Controls) {
      if (controls->has(name)) {
        settings.controls.push_back(
            {std::string(name), controls->integer(name, 0, -1'000'000, 1'000'000)});
      }
    }
    controls->finish();
  }
  source.finish();
  return settings;
}

capture::LibcameraSettings readLibcamera(YamlObject& source) {
  capture::LibcameraSettings settings;
  settings.camera = source.string("libcamera", "");
  refusePreload(source, "libcamera");
  if (!capture::libcameraAvailable()) {
    source.error("libcamera",
                 "this surroundd is built without libcamera cameras: configure with "
                 "-DSURROUNDD_WITH_LIBCAMERA=ON (needs libcamera-dev)");
  }
  settings.fps = source.number("fps", settings.fps, {1.0, 1000.0, false, "frames per second"});
  settings.buffers = source.integer("buffers", settings.buffers, 2, 32);
  settings.timeout = std::chrono::milliseconds(source.integer("timeout_ms", 500, 20, 60'000));
  source.finish();
  return settings;
}

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

processing::Intrinsics readLens(YamlObject& lens, std::string_view camera) {
  processing::Intrinsics in;
  in.model = lens.choice("model", LensModel::kPinhole,
                         {{"pinhole", LensModel::kPinhole},
                          {"fisheye", LensModel::kFisheye},
                          {"ocam", LensModel::kOcam}});
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

}  // namespace

// Default colour role: cameras looking mostly along the vehicle (front, back) are sources, the
// sideways ones targets — the paper's arrangement.
processing::ColourRole defaultRole(const processing::Pose& pose) {
  const cv::Vec3d axis = pose.rotation * cv::Vec3d(0, 0, 1);
  return std::abs(axis[0]) >= std::abs(axis[1]) ? processing::ColourRole::kSource
                                                : processing::ColourRole::kTarget;
}

std::vector<RigCamera> readRigCameras(YamlObject& rig) {
  std::vector<RigCamera> cameras;
  std::set<std::string, std::less<>> names;
  for (auto& entry : rig.objectList("cameras", 1, kMaxCameras)) {
    RigCamera camera;
    auto& calibration = camera.calibration;
    calibration.name = entry.requiredString("name").value_or("");
    // Names become file names (recordings), metric labels and JSON keys.
    const auto allowed = [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_';
    };
    if (!std::ranges::all_of(calibration.name, allowed)) {
      entry.error("name",
                  fmt::format("expected letters, digits, '-' and '_', got '{}'", calibration.name));
    } else if (!calibration.name.empty() && !names.insert(calibration.name).second) {
      entry.error("name", fmt::format("duplicate camera name '{}' (names must be unique)",
                                      calibration.name));
    }
    if (auto lens = entry.object("lens")) {
      calibration.intrinsics = readLens(*lens, calibration.name);
    } else {
      entry.errorHere("missing key 'lens' (model, size and intrinsics)");
    }
    if (auto mount = entry.object("mount")) {
      calibration.pose = readMount(*mount);
    } else {
      entry.errorHere("missing key 'mount' (position and orientation on the vehicle)");
    }
    calibration.role = entry.choice(
        "role", defaultRole(calibration.pose),
        {{"source", processing::ColourRole::kSource}, {"target", processing::ColourRole::kTarget}});
    if (auto health = entry.object("health")) {
      camera.frozenCheck = health->choice(
          "frozen_check", FrozenCheck::kAuto,
          {{"auto", FrozenCheck::kAuto}, {"on", FrozenCheck::kOn}, {"off", FrozenCheck::kOff}});
      health->finish();
    }
    if (auto source = entry.object("source")) {
      if (source->has("device")) {
        camera.device = readDevice(*source);
        camera.device->size = calibration.intrinsics.imageSize;
      } else if (source->has("libcamera")) {
        camera.libcamera = readLibcamera(*source);
        camera.libcamera->size = calibration.intrinsics.imageSize;
      } else {
        camera.source = readSource(*source, camera.preload);
      }
    }
    if (auto mask = entry.object("body_mask")) {
      camera.bodyMask = readBodyMask(*mask, calibration.intrinsics.imageSize);
    }
    entry.finish();
    cameras.push_back(std::move(camera));
  }
  return cameras;
}

std::optional<std::string> lensFieldCutWarning(const processing::CameraCalibration& camera) {
  const auto cut = processing::CameraModel(camera.intrinsics).fieldCut();
  // A turn beyond the picture's corners (common for pinhole calibrations) loses nothing.
  if (!cut || !cut->inImage) return std::nullopt;
  constexpr double kRadToDeg = 180 / std::numbers::pi;
  const auto model = camera.intrinsics.model;
  return fmt::format(
      "camera '{}': the lens's {} polynomial stops increasing {:.1f} degrees off axis, so its "
      "field is cut there ({}); the picture beyond that circle is not used",
      camera.name, model == LensModel::kOcam ? "world_to_image" : "distortion",
      cut->atRad * kRadToDeg,
      model == LensModel::kPinhole
          ? fmt::format("a pinhole lens is otherwise taken up to {:.1f} degrees",
                        cut->askedRad * kRadToDeg)
          : fmt::format("field_of_view_deg asks for {:.1f} degrees",
                        2 * cut->askedRad * kRadToDeg));
}

namespace {

RigFile readRig(const YAML::Node& document, const std::filesystem::path& file) {
  Diagnostics diag;
  YamlObject root(document, "", file, diag);
  RigFile rig;
  rig.cameras = readRigCameras(root);
  if (auto vehicle = root.object("vehicle")) rig.vehicle = readVehicle(*vehicle);
  root.finish();
  diag.throwIfAny();
  return rig;
}

}  // namespace

RigFile loadRig(const std::filesystem::path& file) { return readRig(parseYamlFile(file), file); }

RigFile loadRigText(const std::string& text, const std::filesystem::path& file) {
  return readRig(parseYamlText(text, file), file);
}

std::vector<RigCamera> loadRigFile(const std::filesystem::path& file) {
  return loadRig(file).cameras;
}

namespace {

void emitCamera(YAML::Emitter& out, const RigCamera& camera, const std::filesystem::path& folder) {
  const auto& c = camera.calibration;
  out << YAML::BeginMap;
  out << YAML::Key << "name" << YAML::Value << c.name;
  out << YAML::Key << "role" << YAML::Value
      << (c.role == processing::ColourRole::kSource ? "source" : "target");
  if (camera.source) {
    const auto& path = camera.source->path;
    const bool inside = path.parent_path() == folder;
    out << YAML::Key << "source" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "file" << YAML::Value << (inside ? path.filename() : path).string();
    if (camera.source->loop || capture::isStillPicturePath(path)) {
      out << YAML::Key << "loop" << YAML::Value << camera.source->loop;
    }
    if (camera.source->sequenceFps != capture::FileSourceSettings{}.sequenceFps) {
      out << YAML::Key << "sequence_fps" << YAML::Value << camera.source->sequenceFps;
    }
    if (camera.preload) {
      out << YAML::Key << "preload" << YAML::Value << true;
      for (const auto& [word, format] : kPreloadFormats) {
        if (format == *camera.preload) {
          out << YAML::Key << "format" << YAML::Value << std::string(word);
        }
      }
    }
    out << YAML::EndMap;
  }
  if (camera.libcamera) {
    const auto& l = *camera.libcamera;
    out << YAML::Key << "source" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "libcamera" << YAML::Value << l.camera;
    out << YAML::Key << "fps" << YAML::Value << l.fps;
    out << YAML::Key << "buffers" << YAML::Value << l.buffers;
    out << YAML::Key << "timeout_ms" << YAML::Value << l.timeout.count();
    out << YAML::EndMap;
  }
  if (camera.device) {
    const auto& d = *camera.device;
    out << YAML::Key << "source" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "device" << YAML::Value << d.device.string();
    for (const auto& [word, format] : kV4l2Formats) {
      if (format == d.format) out << YAML::Key << "format" << YAML::Value << std::string(word);
    }
    out << YAML::Key << "fps" << YAML::Value << d.fps;
    out << YAML::Key << "buffers" << YAML::Value << d.buffers;
    out << YAML::Key << "timeout_ms" << YAML::Value << d.timeout.count();
    if (!d.controls.empty()) {
      out << YAML::Key << "controls" << YAML::Value << YAML::BeginMap;
      for (const auto& control : d.controls) {
        out << YAML::Key << control.name << YAML::Value << control.value;
      }
      out << YAML::EndMap;
    }
    out << YAML::EndMap;
  }
  out << YAML::Key << "lens" << YAML::Value << YAML::BeginMap;
  emitLensFields(out, c.intrinsics);
  out << YAML::EndMap;
  if (camera.bodyMask) {
    const auto& mask = *camera.bodyMask;
    out << YAML::Key << "body_mask" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "mode" << YAML::Value
        << (mask.mode == BodyMaskConfig::Mode::kAdd ? "add" : "replace");
    if (!mask.file.empty()) {
      const bool inside = mask.file.parent_path() == folder;
      out << YAML::Key << "file" << YAML::Value
          << (inside ? mask.file.filename() : mask.file).string();
    }
    if (!mask.polygon.empty()) {
      out << YAML::Key << "polygon" << YAML::Value << YAML::BeginSeq;
      for (const auto& [u, v] : mask.polygon) out << YAML::BeginSeq << u << v << YAML::EndSeq;
      out << YAML::EndSeq;
    }
    out << YAML::EndMap;
  }
  const auto angles = processing::mountAnglesFromRotation(c.pose.rotation);
  out << YAML::Key << "mount" << YAML::Value << YAML::Flow << YAML::BeginMap;
  out << YAML::Key << "x_m" << YAML::Value << c.pose.position[0];
  out << YAML::Key << "y_m" << YAML::Value << c.pose.position[1];
  out << YAML::Key << "z_m" << YAML::Value << c.pose.position[2];
  out << YAML::Key << "yaw_deg" << YAML::Value << angles.yawDeg;
  out << YAML::Key << "pitch_deg" << YAML::Value << angles.pitchDeg;
  out << YAML::Key << "roll_deg" << YAML::Value << angles.rollDeg;
  out << YAML::EndMap;
  if (camera.frozenCheck != FrozenCheck::kAuto) {
    out << YAML::Key << "health" << YAML::Value << YAML::Flow << YAML::BeginMap;
    out << YAML::Key << "frozen_check" << YAML::Value
        << (camera.frozenCheck == FrozenCheck::kOn ? "on" : "off");
    out << YAML::EndMap;
  }
  out << YAML::EndMap;
}

}  // namespace

void emitLensFields(YAML::Emitter& out, const processing::Intrinsics& lens) {
  const bool fisheye = lens.model == LensModel::kFisheye;
  const bool ocam = lens.model == LensModel::kOcam;
  out << YAML::Key << "model" << YAML::Value << std::string(processing::lensModelName(lens.model));
  out << YAML::Key << "width_px" << YAML::Value << lens.imageSize.width;
  out << YAML::Key << "height_px" << YAML::Value << lens.imageSize.height;
  if (!ocam) {
    out << YAML::Key << "fx_px" << YAML::Value << lens.fx;
    out << YAML::Key << "fy_px" << YAML::Value << lens.fy;
  }
  out << YAML::Key << "cx_px" << YAML::Value << lens.cx;
  out << YAML::Key << "cy_px" << YAML::Value << lens.cy;
  if (ocam) {
    const auto& o = lens.ocam;
    out << YAML::Key << "affine" << YAML::Value << YAML::Flow << std::vector<double>{o.c, o.d, o.e};
    out << YAML::Key << "world_to_image" << YAML::Value << YAML::Flow << o.worldToImage;
    if (!o.imageToWorld.empty()) {
      out << YAML::Key << "image_to_world" << YAML::Value << YAML::Flow << o.imageToWorld;
    }
  } else {
    out << YAML::Key << "distortion" << YAML::Value << YAML::Flow << YAML::BeginSeq;
    for (std::size_t i = 0; i < (fisheye ? 4U : 5U); ++i) out << lens.distortion[i];
    out << YAML::EndSeq;
  }
  if (fisheye || ocam) {
    out << YAML::Key << "field_of_view_deg" << YAML::Value
        << lens.maxFieldAngleRad * 2 * 180.0 / std::numbers::pi;
  }
}

void writeRigFile(const std::filesystem::path& file, std::span<const RigCamera> cameras,
                  std::string_view headerComment, const VehicleConfig* vehicle) {
  YAML::Emitter out;
  out.SetDoublePrecision(17);  // shortest exact round trip of a double is at most 17 digits
  if (!headerComment.empty()) out << YAML::Comment(std::string(headerComment));
  out << YAML::BeginMap << YAML::Key << "cameras" << YAML::Value << YAML::BeginSeq;
  for (const auto& camera : cameras) emitCamera(out, camera, file.parent_path());
  out << YAML::EndSeq;
  if (vehicle != nullptr) emitVehicle(out, *vehicle);
  out << YAML::EndMap;
  if (!out.good())
    throw ConfigError(
        {fmt::format("{}: cannot write the rig: {}", file.string(), out.GetLastError())});
  // Written beside and renamed, so a reader never sees half a rig.
  const auto partial = std::filesystem::path(file.string() + ".part");
  {
    std::ofstream stream(partial, std::ios::trunc);
    stream << out.c_str() << '\n';
    if (!stream.flush())
      throw ConfigError({fmt::format("{}: cannot write the file", partial.string())});
  }
  std::filesystem::rename(partial, file);
}

}  // namespace surroundd::daemon
