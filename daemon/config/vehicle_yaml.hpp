#pragma once
// The ego vehicle in YAML: one `vehicle:` block (in the config, or in a rig file) that feeds the
// car model of the render, the body masks of the stitcher and the default sizes of the views. Its
// keys (the box's length, width and height, ground clearance, overhangs, offset, or a footprint
// polygon instead; the ground patch's margin; body_masks; the car's own glTF model) are
// vehicleKeys()'s table, with their ranges and docs; config/surroundd.reference.yaml shows them.
//
// Per camera, `body_mask:` adds to or replaces the computed mask: `{file: mask.png}` (white =
// body, the lens's size) and/or `{polygon: [[u, v], ...]}` in pixels (or several:
// `[[[u, v], ...], ...]`, as surround-calibrate mask --from writes them), `mode: add | replace`.

#include <array>
#include <filesystem>
#include <vector>

#include "daemon/config/config_keys.hpp"
#include "daemon/config/yaml_reader.hpp"
#include "processing/vehicle_dimensions.hpp"

namespace surroundd::daemon {

// The vehicle's measurements, and whether the cameras' views of its body are masked out.
struct VehicleConfig : processing::VehicleDimensions {
  bool bodyMasks = true;

  bool operator==(const VehicleConfig&) const = default;
};

struct BodyMaskConfig {
  enum class Mode { kAdd, kReplace } mode = Mode::kAdd;
  std::filesystem::path file;                                // white = body; empty: none
  std::vector<std::vector<std::array<double, 2>>> polygons;  // pixels; empty: none

  bool operator==(const BodyMaskConfig&) const = default;
};

const ConfigKeys<VehicleConfig>& vehicleKeys();
// Reads and validates a `vehicle:` mapping (its table, then the rules across keys); errors go to
// its Diagnostics. The caller finishes the mapping (its unknown keys).
VehicleConfig readVehicle(YamlObject& vehicle);
// A camera's `body_mask:`; its picture must be of the lens's size.
BodyMaskConfig readBodyMask(YamlObject& mask, cv::Size lensSize);
// A body mask's picture in grey levels (white = body); empty where the file holds none that can
// be read.
cv::Mat bodyMaskPicture(const std::filesystem::path& file);

void emitVehicle(YAML::Emitter& out, const VehicleConfig& vehicle);

}  // namespace surroundd::daemon
