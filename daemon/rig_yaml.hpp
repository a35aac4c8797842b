#pragma once
// The rig in YAML: a list of cameras with lens, mount and (for surroundd) a source.
//
//   cameras:
//     - name: front
//       role: source                       # source | target (colour correction)
//       source: {file: front.mkv}          # relative to the file that names it, or a live camera:
//       source: {device: /dev/v4l/by-path/...-video-index0, format: yuyv, fps: 30}
//       source: {libcamera: "/base/soc/i2c0mux/i2c@1/imx219@10"}  # an id, or part of one
//       lens: {model: pinhole, width_px: 1280, height_px: 720, fx_px: .., fy_px: .., cx_px: ..,
//              cy_px: .., distortion: [k1, k2, p1, p2, k3]}
//       mount: {x_m: .., y_m: .., z_m: .., yaw_deg: .., pitch_deg: .., roll_deg: ..}
//       body_mask: {file: front-body.png, mode: add}  # optional, see vehicle_yaml.hpp
//   vehicle: {length_m: .., width_m: .., height_m: ..}  # optional, see vehicle_yaml.hpp
//
// The same schema is used inline in a config (`rig: {cameras: [...]}`) and in a rig file of its own
// (`rig: {file: rig.yaml}`; the generator writes one next to its recordings).

#include <filesystem>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "capture/file_source.hpp"
#include "capture/libcamera_source.hpp"
#include "capture/v4l2_source.hpp"
#include "daemon/vehicle_yaml.hpp"
#include "daemon/yaml_reader.hpp"
#include "processing/rig.hpp"

namespace surroundd::daemon {

struct RigCamera {
  processing::CameraCalibration calibration;
  // Where the frames come from: a file (replay), or a live V4L2 device. Both absent in rig presets
  // (generator input).
  std::optional<capture::FileSourceSettings> source;
  std::optional<capture::V4l2Settings> device;
  std::optional<capture::LibcameraSettings> libcamera;
  std::optional<BodyMaskConfig> bodyMask;  // added to or replacing the vehicle's computed mask
  bool live() const { return device.has_value() || libcamera.has_value(); }
};

struct RigFile {
  std::vector<RigCamera> cameras;
  std::optional<VehicleConfig> vehicle;
};

// Reads and validates the `cameras` list of `rig`; errors go to the object's Diagnostics.
std::vector<RigCamera> readRigCameras(YamlObject& rig);

// A whole rig file; throws ConfigError listing every problem.
RigFile loadRig(const std::filesystem::path& file);
// Its cameras only.
std::vector<RigCamera> loadRigFile(const std::filesystem::path& file);

// Writes a rig file that loadRigFile reads back to the same calibration (doubles round-trip
// exactly). Source paths are written relative to the file's folder when they lie inside it.
void writeRigFile(const std::filesystem::path& file, std::span<const RigCamera> cameras,
                  std::string_view headerComment, const VehicleConfig* vehicle = nullptr);

}  // namespace surroundd::daemon
