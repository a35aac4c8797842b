#pragma once
// The layouts of PJLab SensorsCalibration's surround-camera samples: per-camera JSON files
// (intrinsic/<Cam>.json, extrinsic/<Cam>.json; OpenCV FileStorage reads them) and the plain-YAML
// calibration.yaml of the fisheye sample (K, D, T_cam_from_G per camera).

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "tools/calibrate/import/foreign_calibration.hpp"

namespace surroundd::calibrate {

struct NamedCalibration {
  std::string sourceName;  // as the files spell it ("Front")
  ForeignCalibration calibration;
};

// One camera per DIR/intrinsic/*.json, with DIR/extrinsic/ of the same name; UsageError naming
// the missing file otherwise.
std::vector<std::pair<std::string, std::vector<std::filesystem::path>>> pjlabCameraFiles(
    const std::filesystem::path& dir);

// calibration.yaml: image_size [w, h]; cameras: {<name>: {K: [fx, fy, cx, cy], D: [k1..k4],
// T_cam_from_G: 4x4 rows}}. Read with yaml-cpp (it is not FileStorage YAML).
std::vector<NamedCalibration> readPjlabYaml(const std::filesystem::path& file,
                                            PoseDirection direction);

}  // namespace surroundd::calibrate
