#include "daemon/config/rig_yaml.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <set>
#include <span>

#include <fmt/format.h>

#include "capture/sequence_pattern.hpp"
#include "common/atomic_file.hpp"
#include "common/camera_limit.hpp"
#include "daemon/config/camera_calibration_yaml.hpp"
#include "daemon/config/camera_source_yaml.hpp"
#include "processing/lens/camera_model.hpp"

namespace surroundd::daemon {

using processing::LensModel;

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
      camera.source = readCameraSource(*source, calibration.intrinsics.imageSize);
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
  if (auto vehicle = root.object("vehicle")) {
    rig.vehicle = readVehicle(*vehicle);
    vehicle->finish();
  }
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
    out << YAML::Key << "source" << YAML::Value;
    writeCameraSource(out, *camera.source, folder);
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
    if (!mask.polygons.empty()) {
      const auto emit = [&](const auto& polygon) {
        out << YAML::BeginSeq;
        for (const auto& [u, v] : polygon) out << YAML::BeginSeq << u << v << YAML::EndSeq;
        out << YAML::EndSeq;
      };
      out << YAML::Key << "polygon" << YAML::Value;
      if (mask.polygons.size() == 1) {
        emit(mask.polygons.front());
      } else {
        out << YAML::BeginSeq;
        for (const auto& polygon : mask.polygons) emit(polygon);
        out << YAML::EndSeq;
      }
    }
    out << YAML::EndMap;
  }
  out << YAML::Key << "mount" << YAML::Value << YAML::Flow << YAML::BeginMap;
  emitMountFields(out, c.pose);
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

void emitMountFields(YAML::Emitter& out, const processing::Pose& pose) {
  const auto angles = processing::mountAnglesFromRotation(pose.rotation);
  out << YAML::Key << "x_m" << YAML::Value << pose.position[0];
  out << YAML::Key << "y_m" << YAML::Value << pose.position[1];
  out << YAML::Key << "z_m" << YAML::Value << pose.position[2];
  out << YAML::Key << "yaw_deg" << YAML::Value << angles.yawDeg;
  out << YAML::Key << "pitch_deg" << YAML::Value << angles.pitchDeg;
  out << YAML::Key << "roll_deg" << YAML::Value << angles.rollDeg;
}

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

namespace {

// Where in `node` (a key path, "cameras[1].mount.yaw_deg") the first number that is not finite
// is; none when every number is.
std::optional<std::string> firstNonFiniteNumber(const YAML::Node& node, const std::string& path) {
  if (node.IsScalar()) {
    double value = 0;
    const bool number = YAML::convert<double>::decode(node, value);
    return number && !std::isfinite(value) ? std::optional(path) : std::nullopt;
  }
  if (node.IsSequence()) {
    for (std::size_t i = 0; i < node.size(); ++i) {
      if (auto found = firstNonFiniteNumber(node[i], fmt::format("{}[{}]", path, i))) return found;
    }
  }
  if (node.IsMap()) {
    for (const auto& entry : node) {
      const std::string key = entry.first.Scalar();
      if (auto found = firstNonFiniteNumber(entry.second,
                                            path.empty() ? key : fmt::format("{}.{}", path, key))) {
        return found;
      }
    }
  }
  return std::nullopt;
}

}  // namespace

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
  // A calibration that went wrong upstream (a NaN from a degenerate fit or an imported file) is
  // never written: the daemon would refuse the rig at its next start, far from the cause.
  if (const auto where = firstNonFiniteNumber(YAML::Load(out.c_str()), "")) {
    throw ConfigError({fmt::format("{}: not written: {} is not a finite number (NaN or infinite)",
                                   file.string(), *where)});
  }
  try {
    writeFileAtomically(file, std::string(out.c_str()) + "\n");
  } catch (const std::runtime_error& e) {
    throw ConfigError({e.what()});
  }
}

}  // namespace surroundd::daemon
