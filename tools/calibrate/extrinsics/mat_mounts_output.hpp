#pragma once
// Where a mat calibration's mounts go, for surround-calibrate extrinsics --mat and guide --mat
// alike: only a calibration that passed is written, every camera's mount at once.

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "processing/calibration/mat_calibration.hpp"

namespace surroundd::calibrate {

struct MatMountTargets {
  std::optional<std::filesystem::path> blocks;  // a file of mount: blocks, one per camera
  std::optional<std::filesystem::path> rig;     // a rig file whose cameras' mounts are replaced
};

// Writes every camera's solved mount to the targets, each file whole or not at all (the rig's
// cameras all in one replacement). Returns the files written. When `result` did not pass, writes
// nothing and throws processing::CalibrationError saying how many cameras and seams failed and
// `where` to read why (e.g. "see the table above").
std::vector<std::string> writeMatMounts(const processing::MatCalibration& result,
                                        const MatMountTargets& targets, std::string_view comment,
                                        std::string_view where);

}  // namespace surroundd::calibrate
