#pragma once
// The rig in YAML: a list of cameras with lens, mount and (for surroundd) a source.
//
//   cameras:
//     - name: front
//       role: source                       # source | target (colour correction)
//       source: {file: front.mkv}          # relative to the file that names it, or a live camera:
//       source: {file: front.mkv, preload: true, format: yuyv}  # decoded once into memory, as
//                                          # YUYV, UYVY or NV12, and played from there as a
//                                          camera's
//       source: {device: /dev/v4l/by-path/...-video-index0, format: yuyv, fps: 30}
//       source: {libcamera: "/base/soc/i2c0mux/i2c@1/imx219@10"}  # an id, or part of one
//       lens: {model: pinhole, width_px: 1280, height_px: 720, fx_px: .., fy_px: .., cx_px: ..,
//              cy_px: .., distortion: [k1, k2, p1, p2, k3]}
//       lens: {model: fisheye, ..., distortion: [k1, k2, k3, k4], field_of_view_deg: 190}
//       lens: {model: ocam, width_px: 1280, height_px: 960, cx_px: xc, cy_px: yc,  # OCamCalib
//              affine: [c, d, e], world_to_image: [p0, p1, ...],
//              image_to_world: [a0, a1, ...], field_of_view_deg: 200}
//             # affine defaults to [1, 0, 0], image_to_world is optional; no fx_px, fy_px,
//             # distortion
//       mount: {x_m: .., y_m: .., z_m: .., yaw_deg: .., pitch_deg: .., roll_deg: ..}
//       health: {frozen_check: auto}         # auto | on | off; auto: off for a looped still
//       body_mask: {file: front-body.png, mode: add}  # optional, see vehicle_yaml.hpp
//   vehicle: {length_m: .., width_m: .., height_m: ..}  # optional, see vehicle_yaml.hpp
//
// The same schema is used inline in a config (`rig: {cameras: [...]}`) and in a rig file of its own
// (`rig: {file: rig.yaml}`; the generator writes one next to its recordings).

#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "daemon/config/camera_source_yaml.hpp"
#include "daemon/config/vehicle_yaml.hpp"
#include "daemon/config/yaml_reader.hpp"
#include "processing/rig.hpp"

namespace surroundd::daemon {

// Whether a camera whose frames stop changing is reported frozen. auto: yes, unless its source
// shows one picture by design (a still picture or a one-picture sequence, looped).
enum class FrozenCheck { kAuto, kOn, kOff };

struct RigCamera {
  processing::CameraCalibration calibration;
  // Where the frames come from. None in rig presets (generator input).
  std::optional<CameraSource> source;
  std::optional<BodyMaskConfig> bodyMask;  // added to or replacing the vehicle's computed mask
  FrozenCheck frozenCheck = FrozenCheck::kAuto;
  bool live() const { return source && isLive(*source); }
  // The file it replays; null for a live camera or one with no source.
  const capture::FileSourceSettings* replayedFile() const {
    return source ? daemon::replayedFile(*source) : nullptr;
  }
  capture::FileSourceSettings* replayedFile() {
    return source ? daemon::replayedFile(*source) : nullptr;
  }
  // Replays its file decoded once into memory in `format`, or as it plays (none); see
  // withPreload().
  void preload(std::optional<capture::PixelLayout> format) {
    if (source) source = withPreload(*source, format);
  }
  std::optional<capture::PixelLayout> preloaded() const {
    return source ? preloadFormat(*source) : std::nullopt;
  }
  // Its V4L2 device; null for any other source.
  const capture::V4l2Settings* v4l2() const {
    return source ? std::get_if<capture::V4l2Settings>(&*source) : nullptr;
  }
  capture::V4l2Settings* v4l2() {
    return source ? std::get_if<capture::V4l2Settings>(&*source) : nullptr;
  }
};

struct RigFile {
  std::vector<RigCamera> cameras;
  std::optional<VehicleConfig> vehicle;
};

// The role a camera gets when its entry names none: cameras looking mostly along the vehicle
// (front, back) are colour sources, the sideways ones targets.
processing::ColourRole defaultRole(const processing::Pose& pose);

// Reads and validates the `cameras` list of `rig`; errors go to the object's Diagnostics.
std::vector<RigCamera> readRigCameras(YamlObject& rig);

// A whole rig file; throws ConfigError listing every problem.
RigFile loadRig(const std::filesystem::path& file);
// The same for a rig file's text: `file` is where its relative paths start and what messages name.
RigFile loadRigText(const std::string& text, const std::filesystem::path& file);
// Its cameras only.
std::vector<RigCamera> loadRigFile(const std::filesystem::path& file);

// A warning for a camera whose lens's polynomial stops increasing inside the field it asks for
// while the picture reaches past that angle: the camera model cuts the field there
// (processing::CameraModel::fieldCut), which nobody would notice in the panorama. nullopt when not.
std::optional<std::string> lensFieldCutWarning(const processing::CameraCalibration& camera);

// The keys of one `lens:` map (model, size, intrinsics), into a map the caller has begun. Doubles
// round-trip exactly at the emitter's precision 17.
void emitLensFields(YAML::Emitter& out, const processing::Intrinsics& lens);
// The keys of one `mount:` map (position, then yaw, pitch and roll), likewise.
void emitMountFields(YAML::Emitter& out, const processing::Pose& pose);

// Writes a rig file that loadRigFile reads back to the same calibration (doubles round-trip
// exactly). Source paths are written relative to the file's folder when they lie inside it.
void writeRigFile(const std::filesystem::path& file, std::span<const RigCamera> cameras,
                  std::string_view headerComment, const VehicleConfig* vehicle = nullptr);

}  // namespace surroundd::daemon
