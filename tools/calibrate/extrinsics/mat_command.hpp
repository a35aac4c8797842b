#pragma once
// surround-calibrate extrinsics --mat: every camera a calibration mat names, from one picture
// each; writes the mount: blocks (and updates the rig) only when every camera and seam passed.

#include <filesystem>
#include <ostream>
#include <vector>

#include "processing/calibration/ground_mat.hpp"
#include "processing/rig.hpp"
#include "tools/calibrate/calibrate_options.hpp"

namespace surroundd::calibrate {

// The rig's cameras that the mat names, in rig order. Throws UsageError when a board's seen_by
// names a camera the rig does not have.
std::vector<processing::CameraCalibration> matCameras(const std::filesystem::path& rigFile,
                                                      const std::filesystem::path& matFile,
                                                      const processing::MatLayout& mat);

void runMatExtrinsics(const ExtrinsicsOptions& options, std::ostream& log);

}  // namespace surroundd::calibrate
