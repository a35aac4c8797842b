#include "tools/calibrate/extrinsics/mat_mounts_output.hpp"

#include <fmt/format.h>

#include "processing/calibration/calibration_error.hpp"
#include "tools/calibrate/calibration_output.hpp"

namespace surroundd::calibrate {

std::vector<std::string> writeMatMounts(const processing::MatCalibration& result,
                                        const MatMountTargets& targets, std::string_view comment,
                                        std::string_view where) {
  if (!result.passed()) {
    std::size_t failed = 0;
    for (const auto& camera : result.cameras) failed += camera.passed() ? 0 : 1;
    throw processing::CalibrationError(
        fmt::format("{} of {} cameras failed, {} seam problems ({}); nothing was written", failed,
                    result.cameras.size(), result.problems.size(), where));
  }
  std::vector<std::pair<std::string, processing::Pose>> mounts;
  mounts.reserve(result.cameras.size());
  for (const auto& camera : result.cameras) mounts.emplace_back(camera.camera, camera.solve->pose);
  std::vector<std::string> written;
  if (targets.blocks) {
    writeMountBlocks(*targets.blocks, mounts, comment);
    written.push_back(targets.blocks->string());
  }
  if (targets.rig) {
    updateRigMounts(*targets.rig, mounts, comment);
    written.push_back(targets.rig->string());
  }
  return written;
}

}  // namespace surroundd::calibrate
